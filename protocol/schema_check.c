/* Values against their rows: one value as a patch gives it (schema_apply.c), and every value
 * a struct holds (proto_schema_check). */
#include "schema_text.h"
#include "utc_time.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

bool schema_check_number(struct proto_field_errors *errors, const struct proto_field_desc *field,
                         double value, const char *pointer)
{
    char got[PROTO_FIELD_NUMBER_TEXT_MAX];
    proto_field_format_number(value, got, sizeof got);
    if (!isfinite(value)) {
        proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                "must be a finite number, got %s", got);
        return false;
    }
    char min[PROTO_FIELD_NUMBER_TEXT_MAX], max[PROTO_FIELD_NUMBER_TEXT_MAX];
    proto_field_format_number(field->min, min, sizeof min);
    proto_field_format_number(field->max, max, sizeof max);
    if (field->exclusive_min && value <= field->min) {
        if (value > field->max)
            proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                    "must be in (%s, %s], got %s", min, max, got);
        else
            proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                    "must be greater than %s, got %s", min, got);
        return false;
    }
    if (value < field->min || value > field->max) {
        proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                "must be in %s%s, %s], got %s", field->exclusive_min ? "(" : "[",
                                min, max, got);
        return false;
    }
    return true;
}

/* The range check comes first, so an integral value is known to fit the field's integer. */
bool schema_check_integer(struct proto_field_errors *errors, const struct proto_field_desc *field,
                          double value, const char *pointer)
{
    if (!schema_check_number(errors, field, value, pointer))
        return false;
    if (value != floor(value)) {
        char got[PROTO_FIELD_NUMBER_TEXT_MAX];
        proto_field_format_number(value, got, sizeof got);
        proto_field_errors_addf(errors, PROTO_FIELD_BAD_VALUE, pointer,
                                "must be an integer, got %s", got);
        return false;
    }
    return true;
}

bool schema_check_time(struct proto_field_errors *errors, const struct proto_field_desc *field,
                       double seconds, const char *pointer)
{
    if (isfinite(seconds) && seconds >= field->min && seconds <= field->max)
        return true;
    char got[TIME_TEXT_CAPACITY], min[TIME_TEXT_CAPACITY], max[TIME_TEXT_CAPACITY];
    proto_time_format_iso8601(seconds, got, sizeof got);
    proto_time_format_iso8601(field->min, min, sizeof min);
    proto_time_format_iso8601(field->max, max, sizeof max);
    proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                            "must be in [%s, %s], got %s", min, max, got);
    return false;
}

static void check_stored_field(const void *base, const struct proto_field_desc *field,
                               struct proto_field_errors *errors)
{
    char pointer[POINTER_CAPACITY];
    char item_pointer[POINTER_CAPACITY];
    schema_pointer_from_dotted(field->path, pointer, sizeof pointer);
    const void *address = (const char *)base + field->offset;
    int count = schema_element_count(field->type);

    switch (field->type) {
    case PROTO_FIELD_TYPE_NUMBER:
        schema_check_number(errors, field, *(const double *)address, pointer);
        break;
    case PROTO_FIELD_TYPE_RGB:
        for (int i = 0; i < count; i++) {
            schema_element_pointer(pointer, i, item_pointer, sizeof item_pointer);
            schema_check_number(errors, field, ((const double *)address)[i], item_pointer);
        }
        break;
    case PROTO_FIELD_TYPE_INT_PAIR:
    case PROTO_FIELD_TYPE_INT_TRIPLE:
        for (int i = 0; i < count; i++) {
            schema_element_pointer(pointer, i, item_pointer, sizeof item_pointer);
            schema_check_number(errors, field, ((const int *)address)[i], item_pointer);
        }
        break;
    case PROTO_FIELD_TYPE_INT:
        schema_check_number(errors, field, *(const int *)address, pointer);
        break;
    case PROTO_FIELD_TYPE_INT64:
        schema_check_number(errors, field, (double)*(const int64_t *)address, pointer);
        break;
    case PROTO_FIELD_TYPE_TIME:
        schema_check_time(errors, field, *(const double *)address, pointer);
        break;
    case PROTO_FIELD_TYPE_ENUM: {
        int value = *(const int *)address;
        if (value < 0 || value >= field->enum_count || !field->enum_names[value]) {
            char names[REASON_CAPACITY];
            schema_list_enum_names(field, names, sizeof names);
            proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer,
                                    "must be one of: %s, got %d", names, value);
        }
        break;
    }
    case PROTO_FIELD_TYPE_STRING:
        if (!memchr(address, '\0', field->capacity))
            proto_field_errors_addf(errors, PROTO_FIELD_OUT_OF_RANGE, pointer, "not terminated");
        break;
    case PROTO_FIELD_TYPE_BOOL:
        break;
    }
}

bool proto_schema_check(const struct proto_schema *schema, const void *base,
                        struct proto_field_errors *errors)
{
    int before = errors->total;
    for (size_t i = 0; i < schema->count; i++)
        check_stored_field(base, &schema->fields[i], errors);
    return errors->total == before;
}
