/* Reports the METAR decoder must refuse: each malformed group named with its index and offset
 * and a stable error code, truncated reports, garbage, groups out of order, limits, characters
 * no report holds; and the report zeroed on refusal. */
#include "test_metar.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* clang-format off */
static const struct {
    const char *text;
    enum proto_metar_error_code code;
    int group;      /* 0: the report as a whole */
    size_t offset;
    const char *reason; /* part of the message after the group's name */
} refusals[] = {
    {"METAR EGLL 281250Z 24015KT 9999 BKN0X0 12/08 Q1002", PROTO_METAR_ERR_CLOUD, 6, 32,
     "cloud height must be three digits (hundreds of feet) or ///"},
    {"", PROTO_METAR_ERR_EMPTY, 0, 0, "no group"},
    {" \r\n\t ", PROTO_METAR_ERR_EMPTY, 0, 0, "no group"},
    {"=", PROTO_METAR_ERR_EMPTY, 0, 0, "no group"},
    /* Truncated: the error names the last group and what should follow it. */
    {"METAR", PROTO_METAR_ERR_MISSING, 1, 0, "without the station"},
    {"METAR EGLL", PROTO_METAR_ERR_MISSING, 2, 6, "without the observation time"},
    {"METAR EGLL 281250Z", PROTO_METAR_ERR_MISSING, 3, 11, "without the wind group"},
    {"METAR EGLL 281250Z 24015KT=", PROTO_METAR_ERR_MISSING, 4, 19, "without the visibility"},
    {"METAR EGLL 281250Z 24015KT 9999 FEW020", PROTO_METAR_ERR_MISSING, 6, 32,
     "without the temperature and dew point"},
    {"METAR EGLL 281250Z 9999 FEW020 12/08", PROTO_METAR_ERR_MISSING, 4, 19,
     "expected the wind group"},
    {"METAR EGLL 281250Z 24015KT FEW020 12/08", PROTO_METAR_ERR_MISSING, 5, 27,
     "expected the visibility"},
    /* Identification. */
    {"METAR EGL 281250Z 24015KT 9999 12/08", PROTO_METAR_ERR_STATION, 2, 6, "location indicator"},
    {"METAR 1GLL 281250Z 24015KT 9999 12/08", PROTO_METAR_ERR_STATION, 2, 6, "location indicator"},
    {"METAR EGLL 321250Z 24015KT 9999 12/08", PROTO_METAR_ERR_TIME, 3, 11, "day 32"},
    {"METAR EGLL 282450Z 24015KT 9999 12/08", PROTO_METAR_ERR_TIME, 3, 11, "hour 24"},
    {"METAR EGLL 281260Z 24015KT 9999 12/08", PROTO_METAR_ERR_TIME, 3, 11, "minute 60"},
    {"METAR EGLL 281250 24015KT 9999 12/08", PROTO_METAR_ERR_TIME, 3, 11, "ddhhmmZ"},
    {"METAR EGLL 281250Z AUTO AUTO 24015KT 9999 12/08", PROTO_METAR_ERR_UNEXPECTED, 5, 24,
     "given twice"},
    {"METAR EGLL 281250Z NIL 24015KT", PROTO_METAR_ERR_UNEXPECTED, 5, 23, "cannot come after"},
    /* Wind. */
    {"METAR EGLL 281250Z 24O15KT 9999 12/08", PROTO_METAR_ERR_WIND, 4, 19, "dddff"},
    {"METAR EGLL 281250Z 37015KT 9999 12/08", PROTO_METAR_ERR_WIND, 4, 19, "direction 370"},
    {"METAR EGLL 281250Z 24015G10KT 9999 12/08", PROTO_METAR_ERR_WIND, 4, 19, "gust 10"},
    {"METAR EGLL 281250Z 24015GKT 9999 12/08", PROTO_METAR_ERR_WIND, 4, 19, "a gust must be"},
    {"METAR EGLL 281250Z 2401KT 9999 12/08", PROTO_METAR_ERR_WIND, 4, 19, "dddff"},
    {"METAR EGLL 281250Z 00000G20KT 9999 12/08", PROTO_METAR_ERR_WIND, 4, 19, "calm"},
    {"METAR EGLL 281250Z 24015KT 240V240 9999 12/08", PROTO_METAR_ERR_WIND, 5, 27, "equal"},
    {"METAR EGLL 281250Z 24015KT 240V3X0 9999 12/08", PROTO_METAR_ERR_WIND, 5, 27, "dddVddd"},
    /* Visibility and runways. */
    {"METAR KXYZ 281250Z 24015KT 2/3SM 12/08", PROTO_METAR_ERR_VISIBILITY, 5, 27, "1/2SM"},
    {"METAR KXYZ 281250Z 24015KT 1 3/2SM 12/08", PROTO_METAR_ERR_VISIBILITY, 6, 29, "1/2SM"},
    {"METAR KXYZ 281250Z 24015KT 0SM 12/08", PROTO_METAR_ERR_VISIBILITY, 5, 27, "1/2SM"},
    {"METAR EGLL 281250Z 24015KT 4000 1500XX 12/08", PROTO_METAR_ERR_VISIBILITY, 6, 32, "direction"},
    {"METAR EGLL 281250Z 24015KT 0600 R27/P15OON 12/08", PROTO_METAR_ERR_RVR, 6, 32, "R24/P2000N"},
    {"METAR EGLL 281250Z 24015KT 0600 R27P1500N 12/08", PROTO_METAR_ERR_RVR, 6, 32, "R24/P2000N"},
    {"METAR EGLL 281250Z 24015KT 0600 R27/P1500N R09/1000U R01/1200N R02/1200N R03/1200N 12/08",
     PROTO_METAR_ERR_TOO_MANY, 10, 73, "more than 4 runway"},
    {"METAR EGLL 281250Z 24015KT 0600 R24/290050 12/08", PROTO_METAR_ERR_UNEXPECTED, 6, 32,
     "this supplementary group cannot come after the visibility group"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 R24/CLRDX0", PROTO_METAR_ERR_RVR, 8, 44,
     "runway state"},
    /* Present weather. */
    {"METAR EGLL 281250Z 24015KT 9999 +XX 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "unknown weather"},
    {"METAR EGLL 281250Z 24015KT 9999 RAXX 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "\"XX\""},
    {"METAR EGLL 281250Z 24015KT 9999 SHFG 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "SH cannot qualify FG"},
    {"METAR EGLL 281250Z 24015KT 9999 -FG 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "intensity"},
    {"METAR EGLL 281250Z 24015KT 9999 RARA 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "twice"},
    {"METAR EGLL 281250Z 24015KT 9999 FGBR 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "only precipitation"},
    {"METAR EGLL 281250Z 24015KT 9999 FZ 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "needs a phenomenon"},
    {"METAR EGLL 281250Z 24015KT 9999 RAS 12/08", PROTO_METAR_ERR_WEATHER, 6, 32, "pairs of letters"},
    {"METAR EGLL 281250Z 24015KT 9999 -RA BR VCSH +SN 12/08", PROTO_METAR_ERR_TOO_MANY, 9, 44,
     "more than 3 present-weather"},
    /* Clouds. */
    {"METAR EGLL 281250Z 24015KT 9999 SCT020CBX 12/08", PROTO_METAR_ERR_CLOUD, 6, 32, "CB, TCU or ///"},
    {"METAR EGLL 281250Z 24015KT 9999 BKN 12/08", PROTO_METAR_ERR_CLOUD, 6, 32, "three digits"},
    {"METAR EGLL 281250Z 24015KT 9999 VV1 12/08", PROTO_METAR_ERR_CLOUD, 6, 32, "VV///"},
    {"METAR EGLL 281250Z 24015KT 9999 FEW020 NSC 12/08", PROTO_METAR_ERR_CLOUD, 7, 39, "NSC cannot"},
    {"METAR EGLL 281250Z 24015KT 9999 VV002 FEW020 12/08", PROTO_METAR_ERR_CLOUD, 7, 38, "obscured"},
    {"METAR EGLL 281250Z 24015KT 9999 FEW010 FEW020 SCT030 SCT040 BKN050 BKN060 OVC070 12/08",
     PROTO_METAR_ERR_TOO_MANY, 12, 74, "more than 6 cloud layers"},
    /* Temperature, pressure, supplementary. */
    {"METAR EGLL 281250Z 24015KT 9999 12/8 Q1002", PROTO_METAR_ERR_TEMPERATURE, 6, 32, "TT/TdTd"},
    {"METAR EGLL 281250Z 24015KT 9999 M1/08 Q1002", PROTO_METAR_ERR_TEMPERATURE, 6, 32, "TT/TdTd"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1200", PROTO_METAR_ERR_PRESSURE, 7, 38, "QNH 1200"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 A29X2", PROTO_METAR_ERR_PRESSURE, 7, 38, "four digits"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 WS R2", PROTO_METAR_ERR_SUPPLEMENTARY, 9, 47, "runway"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 WS ALL", PROTO_METAR_ERR_SUPPLEMENTARY, 9, 47, "ALL RWY"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 WS", PROTO_METAR_ERR_SUPPLEMENTARY, 8, 44, "runway"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 REXX", PROTO_METAR_ERR_WEATHER, 8, 44, "recent"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 W1/S2", PROTO_METAR_ERR_SUPPLEMENTARY, 8, 44, "sea"},
    /* Out of order, garbage, CAVOK with what it excludes. */
    {"METAR EGLL 281250Z 24015KT 9999 FEW020 12/08 9999 Q1002", PROTO_METAR_ERR_UNEXPECTED, 8, 45,
     "this visibility group cannot come after the temperature group"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 FEW020", PROTO_METAR_ERR_UNEXPECTED, 7, 38,
     "this cloud group cannot come after"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 R27/P1500N", PROTO_METAR_ERR_UNEXPECTED, 7, 38,
     "this runway group cannot come after"},
    {"METAR EGLL 281250Z 24015KT CAVOK FEW020 12/08", PROTO_METAR_ERR_UNEXPECTED, 6, 33, "CAVOK"},
    {"METAR EGLL 281250Z 24015KT CAVOK -RA 12/08", PROTO_METAR_ERR_UNEXPECTED, 6, 33, "CAVOK"},
    {"METAR EGLL 281250Z 24015KT 9999 XYZ FEW020 12/08", PROTO_METAR_ERR_UNEXPECTED, 6, 32,
     "not a METAR group"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 FOO", PROTO_METAR_ERR_UNEXPECTED, 8, 44,
     "not a METAR group"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 12/08", PROTO_METAR_ERR_UNEXPECTED, 7, 38,
     "temperature group cannot come after the temperature"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 Q1002 Q1002", PROTO_METAR_ERR_TOO_MANY, 9, 50,
     "more than 2 pressure"},
    /* Characters and the end of the report. */
    {"metar EGLL 281250Z 24015KT 9999 12/08", PROTO_METAR_ERR_CHARACTER, 1, 0, "0x6d 'm' at offset 0"},
    {"METAR EGLL 281250Z 24015KT 99\00199 12/08", PROTO_METAR_ERR_CHARACTER, 5, 27, "0x01 at offset 29 is not allowed"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 RMK \303\251t\303\251", PROTO_METAR_ERR_CHARACTER, 8, 42,
     "0xc3 at offset 42"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08= Q1002", PROTO_METAR_ERR_AFTER_END, 0, 39,
     "offset 39: text after the '=' that ends the report at offset 37"},
    {"METAR EGLL 281250Z 24015KT 9999 12/08 Q1002 NOSIG ABCDEFGHIJKLMNOPQRSTUVWXYZ",
     PROTO_METAR_ERR_TOO_LONG, 9, 50, "26 characters"},
};
/* clang-format on */

static void test_table(void)
{
    for (size_t i = 0; i < sizeof refusals / sizeof refusals[0]; i++) {
        check_case_name = refusals[i].text;
        size_t length = strlen(refusals[i].text);
        struct proto_metar_report report;
        struct proto_metar_error error;
        memset(&report, 0x5a, sizeof report);
        CHECK(!proto_metar_decode(refusals[i].text, length, &report, &error));
        CHECK_INT(error.code, refusals[i].code);
        CHECK_INT(error.group, refusals[i].group);
        CHECK_INT(error.offset, refusals[i].offset);
        CHECK_CONTAINS(error.message, refusals[i].reason);
        if (refusals[i].group > 0) {
            /* `group N "TEXT" (offset X): ...` names the group as the report wrote it. */
            char prefix[96];
            snprintf(prefix, sizeof prefix, "group %d \"%s\" (offset %zu): ", error.group,
                     error.group_text, error.offset);
            CHECK(strncmp(error.message, prefix, strlen(prefix)) == 0);
            CHECK(error.offset < length);
            CHECK(error.offset >= length ||
                  strncmp(refusals[i].text + error.offset, error.group_text,
                          strlen(error.group_text)) == 0 ||
                  error.code == PROTO_METAR_ERR_CHARACTER);
        }
        /* A refused report leaves nothing behind. */
        static const struct proto_metar_report zero;
        CHECK(memcmp(&report, &zero, sizeof report) == 0);
    }
    check_case_name = "";
}

static void test_limits(void)
{
    struct proto_metar_report report;
    struct proto_metar_error error;
    /* Over the length limit, however valid the start. */
    char *text = malloc(PROTO_METAR_MAX_LENGTH + 2);
    if (!text)
        return;
    int n = snprintf(text, PROTO_METAR_MAX_LENGTH + 2,
                     "METAR EGLL 281250Z 24015KT 9999 12/08 RMK ");
    memset(text + n, 'X', PROTO_METAR_MAX_LENGTH + 1 - (size_t)n);
    text[PROTO_METAR_MAX_LENGTH + 1] = '\0';
    CHECK(!proto_metar_decode(text, PROTO_METAR_MAX_LENGTH + 1, &report, &error));
    CHECK_INT(error.code, PROTO_METAR_ERR_TOO_LONG);
    CHECK_INT(error.group, 0);
    CHECK_CONTAINS(error.message, "1025 characters");
    free(text);

    /* More groups before RMK than the limit (a trend of many groups). */
    char many[PROTO_METAR_MAX_LENGTH];
    size_t used = (size_t)snprintf(many, sizeof many,
                                   "METAR EGLL 281250Z 24015KT 9999 12/08 TEMPO");
    for (int i = 8; i <= PROTO_METAR_MAX_GROUPS; i++)
        used += (size_t)snprintf(many + used, sizeof many - used, " 9999");
    CHECK(proto_metar_decode(many, used, &report, &error)); /* exactly the limit */
    used += (size_t)snprintf(many + used, sizeof many - used, " 9999");
    CHECK(!proto_metar_decode(many, used, &report, &error));
    CHECK_INT(error.code, PROTO_METAR_ERR_TOO_MANY);
    CHECK_INT(error.group, PROTO_METAR_MAX_GROUPS + 1);
    CHECK_CONTAINS(error.message, "more than 64 groups");

    /* A NUL inside the given length is a character like any other. */
    static const char with_nul[] = "METAR EGLL 281250Z 24015KT 9999\0 12/08";
    CHECK(!proto_metar_decode(with_nul, sizeof with_nul - 1, &report, &error));
    CHECK_INT(error.code, PROTO_METAR_ERR_CHARACTER);
    CHECK_INT(error.offset, 27);

    /* No error structure wanted; a NULL text is empty. */
    CHECK(!proto_metar_decode("METAR EGLL", 10, &report, NULL));
    CHECK(!proto_metar_decode(NULL, 5, &report, &error));
    CHECK_INT(error.code, PROTO_METAR_ERR_EMPTY);
}

void test_metar_refusals(void)
{
    test_table();
    test_limits();
}
