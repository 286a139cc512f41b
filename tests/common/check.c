/* The counters and case name of check.h, one set per test executable, so that a test split
 * over several files counts every check in one summary. */
#include "check.h"

int check_passed, check_failed;
const char *check_case_name = "";
