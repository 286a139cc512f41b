/* Checks for the table-driven suites: each failure prints file, line, the current case's
 * name, the expressions and their values; the suite prints "N passed, M failed" at the end
 * from checks_passed and checks_failed. Set current_case while running a table row. */
#ifndef SKYD_TEST_CHECK_CASES_H
#define SKYD_TEST_CHECK_CASES_H

#include <stdbool.h>
#include <stdio.h>
#include <string.h>

static int checks_passed;
static int checks_failed;
static const char *current_case = "";

static inline bool record(bool ok, const char *file, int line)
{
    if (ok) {
        checks_passed++;
        return true;
    }
    checks_failed++;
    printf("%s:%d: [%s] ", file, line, current_case);
    return false;
}

static inline void check_true(bool ok, const char *expression, const char *file, int line)
{
    if (!record(ok, file, line))
        printf("CHECK(%s) failed\n", expression);
}

static inline void check_int(long long actual, long long expected, const char *actual_text,
                      const char *expected_text, const char *file, int line)
{
    if (!record(actual == expected, file, line))
        printf("CHECK_INT(%s, %s) failed: %lld != %lld\n", actual_text, expected_text, actual,
               expected);
}

static inline void check_double(double actual, double expected, const char *actual_text,
                         const char *expected_text, const char *file, int line)
{
    if (!record(actual == expected, file, line))
        printf("CHECK_DOUBLE(%s, %s) failed: %.17g != %.17g\n", actual_text, expected_text,
               actual, expected);
}

static inline void check_str(const char *actual, const char *expected, const char *actual_text,
                      const char *expected_text, const char *file, int line)
{
    bool ok = actual && expected && strcmp(actual, expected) == 0;
    if (!record(ok, file, line))
        printf("CHECK_STR(%s, %s) failed: \"%s\" != \"%s\"\n", actual_text, expected_text,
               actual ? actual : "(null)", expected ? expected : "(null)");
}

static inline void check_contains(const char *text, const char *part, const char *text_expression,
                           const char *part_expression, const char *file, int line)
{
    bool ok = text && part && strstr(text, part) != NULL;
    if (!record(ok, file, line))
        printf("CHECK_CONTAINS(%s, %s) failed: \"%s\" does not contain \"%s\"\n", text_expression,
               part_expression, text ? text : "(null)", part ? part : "(null)");
}

#define CHECK(cond) check_true((cond), #cond, __FILE__, __LINE__)
#define CHECK_INT(a, b) check_int((long long)(a), (long long)(b), #a, #b, __FILE__, __LINE__)
#define CHECK_DOUBLE(a, b) check_double((a), (b), #a, #b, __FILE__, __LINE__)
#define CHECK_STR(a, b) check_str((a), (b), #a, #b, __FILE__, __LINE__)
#define CHECK_CONTAINS(text, part) check_contains((text), (part), #text, #part, __FILE__, __LINE__)

#endif
