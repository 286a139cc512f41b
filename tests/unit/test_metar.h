/* The METAR decoder's tests (protocol/metar_*.c), shared by their files. */
#ifndef SKYD_TEST_METAR_H
#define SKYD_TEST_METAR_H

#include <stdbool.h>

#include "metar.h"

/* Decodes text, counting a check that it was accepted (printing the error when not). */
bool decode_ok(const char *text, struct proto_metar_report *report);

/* test_metar_refusals.c: malformed, truncated, garbage and overlong reports. */
void test_metar_refusals(void);

#endif
