/* Minimal test checks: each failure prints the expression and the values; a run ends with
 * "N passed, M failed" and the exit status says whether anything failed. */
#ifndef SKYD_TEST_CHECK_H
#define SKYD_TEST_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_passed, check_failed;

#define CHECK(cond)                                                                       \
    do {                                                                                  \
        if (cond) {                                                                       \
            check_passed++;                                                               \
        } else {                                                                          \
            check_failed++;                                                               \
            printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);                       \
        }                                                                                 \
    } while (0)

/* |a - b| <= tol, printing both values on failure. */
#define CHECK_NEAR(a, b, tol)                                                             \
    do {                                                                                  \
        double check_a_ = (a), check_b_ = (b), check_t_ = (tol);                          \
        if (fabs(check_a_ - check_b_) <= check_t_) {                                      \
            check_passed++;                                                               \
        } else {                                                                          \
            check_failed++;                                                               \
            printf("FAIL %s:%d: %s = %.9g, %s = %.9g, |diff| %.3g > %.3g\n", __FILE__,    \
                   __LINE__, #a, check_a_, #b, check_b_, fabs(check_a_ - check_b_),       \
                   check_t_);                                                             \
        }                                                                                 \
    } while (0)

/* a <= b, printing both on failure. */
#define CHECK_LE(a, b)                                                                    \
    do {                                                                                  \
        double check_a_ = (a), check_b_ = (b);                                            \
        if (check_a_ <= check_b_) {                                                       \
            check_passed++;                                                               \
        } else {                                                                          \
            check_failed++;                                                               \
            printf("FAIL %s:%d: %s = %.9g > %s = %.9g\n", __FILE__, __LINE__, #a,         \
                   check_a_, #b, check_b_);                                               \
        }                                                                                 \
    } while (0)

/* CHECK with a printf-style explanation on failure. */
#define CHECK_MSG(cond, ...)                                                              \
    do {                                                                                  \
        if (cond) {                                                                       \
            check_passed++;                                                               \
        } else {                                                                          \
            check_failed++;                                                               \
            printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);                       \
            printf(__VA_ARGS__);                                                          \
            printf("\n");                                                                \
        }                                                                                 \
    } while (0)

static inline int check_summary(void)
{
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed ? 1 : 0;
}

#endif
