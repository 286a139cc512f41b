/* The tests' one check framework: each failure prints "FAIL file:line:", the current case's
 * name when a table-driven suite set one (check_case_name), the expression and the values; a run
 * ends with check_summary(), "N passed, M failed", whose result is the exit status. */
#ifndef SKYD_TEST_CHECK_H
#define SKYD_TEST_CHECK_H

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

/* Shared by every file of a test executable (defined in check.c). */
extern int check_passed, check_failed;
/* The table row being run: printed with every failure while it is not empty. */
extern const char *check_case_name;

/* Counts one check; on failure prints its place, leaving the line open for the details. */
static inline bool check_record(bool ok, const char *file, int line)
{
    if (ok) {
        check_passed++;
        return true;
    }
    check_failed++;
    printf("FAIL %s:%d: ", file, line);
    if (check_case_name && check_case_name[0])
        printf("[%s] ", check_case_name);
    return false;
}

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!check_record((cond), __FILE__, __LINE__))                                             \
            printf("%s\n", #cond);                                                                 \
    } while (0)

/* |a - b| <= tol, printing both values on failure. */
#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double check_a_ = (a), check_b_ = (b), check_t_ = (tol);                                   \
        if (!check_record(fabs(check_a_ - check_b_) <= check_t_, __FILE__, __LINE__))              \
            printf("%s = %.9g, %s = %.9g, |diff| %.3g > %.3g\n", #a, check_a_, #b, check_b_,       \
                   fabs(check_a_ - check_b_), check_t_);                                           \
    } while (0)

/* a <= b, printing both on failure. */
#define CHECK_LE(a, b)                                                                             \
    do {                                                                                           \
        double check_a_ = (a), check_b_ = (b);                                                     \
        if (!check_record(check_a_ <= check_b_, __FILE__, __LINE__))                               \
            printf("%s = %.9g > %s = %.9g\n", #a, check_a_, #b, check_b_);                         \
    } while (0)

/* CHECK with a printf-style explanation on failure. */
#define CHECK_MSG(cond, ...)                                                                       \
    do {                                                                                           \
        if (!check_record((cond), __FILE__, __LINE__)) {                                           \
            printf("%s: ", #cond);                                                                 \
            printf(__VA_ARGS__);                                                                   \
            printf("\n");                                                                          \
        }                                                                                          \
    } while (0)

static inline void check_int(long long actual, long long expected, const char *actual_text,
                             const char *expected_text, const char *file, int line)
{
    if (!check_record(actual == expected, file, line))
        printf("CHECK_INT(%s, %s): %lld != %lld\n", actual_text, expected_text, actual, expected);
}

static inline void check_double(double actual, double expected, const char *actual_text,
                                const char *expected_text, const char *file, int line)
{
    if (!check_record(actual == expected, file, line))
        printf("CHECK_DOUBLE(%s, %s): %.17g != %.17g\n", actual_text, expected_text, actual,
               expected);
}

static inline void check_str(const char *actual, const char *expected, const char *actual_text,
                             const char *expected_text, const char *file, int line)
{
    bool ok = actual && expected && strcmp(actual, expected) == 0;
    if (!check_record(ok, file, line))
        printf("CHECK_STR(%s, %s): \"%s\" != \"%s\"\n", actual_text, expected_text,
               actual ? actual : "(null)", expected ? expected : "(null)");
}

static inline void check_contains(const char *text, const char *part, const char *text_expression,
                                  const char *part_expression, const char *file, int line)
{
    bool ok = text && part && strstr(text, part) != NULL;
    if (!check_record(ok, file, line))
        printf("CHECK_CONTAINS(%s, %s): \"%s\" does not contain \"%s\"\n", text_expression,
               part_expression, text ? text : "(null)", part ? part : "(null)");
}

/* Exact comparisons (table-driven suites). */
#define CHECK_INT(a, b) check_int((long long)(a), (long long)(b), #a, #b, __FILE__, __LINE__)
#define CHECK_DOUBLE(a, b) check_double((a), (b), #a, #b, __FILE__, __LINE__)
#define CHECK_STR(a, b) check_str((a), (b), #a, #b, __FILE__, __LINE__)
#define CHECK_CONTAINS(text, part) check_contains((text), (part), #text, #part, __FILE__, __LINE__)

static inline int check_summary(void)
{
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed ? 1 : 0;
}

#endif
