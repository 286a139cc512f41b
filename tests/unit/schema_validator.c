#include "schema_validator.h"

#include <math.h>
#include <regex.h>
#include <stdio.h>
#include <string.h>

static bool is_date_time(const char *s)
{
    int y, mo, d, h, mi;
    double sec;
    char z;
    return sscanf(s, "%4d-%2d-%2dT%2d:%2d:%lf%c", &y, &mo, &d, &h, &mi, &sec, &z) == 7 && z == 'Z';
}

static const cJSON *keyword(const cJSON *schema, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(schema, name);
}

static bool conforms_type(const cJSON *schema, const cJSON *value)
{
    const cJSON *type = keyword(schema, "type");
    if (!type)
        return true;
    const char *t = type->valuestring;
    if (strcmp(t, "object") == 0)
        return cJSON_IsObject(value);
    if (strcmp(t, "array") == 0)
        return cJSON_IsArray(value);
    if (strcmp(t, "string") == 0)
        return cJSON_IsString(value);
    if (strcmp(t, "number") == 0)
        return cJSON_IsNumber(value);
    if (strcmp(t, "boolean") == 0)
        return cJSON_IsBool(value);
    if (strcmp(t, "integer") == 0)
        return cJSON_IsNumber(value) && value->valuedouble == floor(value->valuedouble);
    return false;
}

static bool conforms_number(const cJSON *schema, double value)
{
    const cJSON *k;
    if ((k = keyword(schema, "minimum")) && value < k->valuedouble)
        return false;
    if ((k = keyword(schema, "exclusiveMinimum")) && value <= k->valuedouble)
        return false;
    if ((k = keyword(schema, "maximum")) && value > k->valuedouble)
        return false;
    return true;
}

/* Lengths in characters (code points), as JSON Schema counts them. */
static bool conforms_string(const cJSON *schema, const char *value)
{
    const cJSON *k;
    size_t characters = 0;
    for (const unsigned char *c = (const unsigned char *)value; *c; c++)
        characters += (*c & 0xC0) != 0x80;
    if ((k = keyword(schema, "minLength")) && characters < (size_t)k->valueint)
        return false;
    if ((k = keyword(schema, "maxLength")) && characters > (size_t)k->valueint)
        return false;
    if ((k = keyword(schema, "format")) && strcmp(k->valuestring, "date-time") == 0 &&
        !is_date_time(value))
        return false;
    if ((k = keyword(schema, "pattern"))) {
        regex_t pattern;
        if (regcomp(&pattern, k->valuestring, REG_EXTENDED | REG_NOSUB) != 0)
            return false;
        bool match = regexec(&pattern, value, 0, NULL, 0) == 0;
        regfree(&pattern);
        return match;
    }
    return true;
}

static bool conforms_object(const cJSON *root, const cJSON *schema, const cJSON *value)
{
    const cJSON *properties = keyword(schema, "properties");
    const cJSON *closed = keyword(schema, "additionalProperties");
    const cJSON *member, *name;
    cJSON_ArrayForEach(member, value)
    {
        const cJSON *sub = cJSON_GetObjectItemCaseSensitive(properties, member->string);
        if (!sub && cJSON_IsFalse(closed))
            return false;
        if (sub && !schema_conforms(root, sub, member))
            return false;
    }
    cJSON_ArrayForEach(name, keyword(schema, "required"))
    {
        if (!cJSON_GetObjectItemCaseSensitive(value, name->valuestring))
            return false;
    }
    cJSON_ArrayForEach(member, keyword(schema, "dependentSchemas"))
    {
        if (cJSON_GetObjectItemCaseSensitive(value, member->string) &&
            !schema_conforms(root, member, value))
            return false;
    }
    return true;
}

bool schema_conforms(const cJSON *root, const cJSON *schema, const cJSON *value)
{
    const cJSON *k;
    if ((k = keyword(schema, "$ref"))) {
        const char *prefix = "#/$defs/";
        if (strncmp(k->valuestring, prefix, strlen(prefix)) != 0)
            return false;
        const cJSON *target = keyword(keyword(root, "$defs"), k->valuestring + strlen(prefix));
        if (!target || !schema_conforms(root, target, value))
            return false;
    }
    if (!conforms_type(schema, value))
        return false;
    if ((k = keyword(schema, "const")) && !cJSON_Compare(k, value, true))
        return false;
    if ((k = keyword(schema, "enum"))) {
        bool found = false;
        const cJSON *name;
        cJSON_ArrayForEach(name, k) found |= cJSON_Compare(name, value, true);
        if (!found)
            return false;
    }
    if (cJSON_IsNumber(value) && !conforms_number(schema, value->valuedouble))
        return false;
    if (cJSON_IsString(value) && !conforms_string(schema, value->valuestring))
        return false;
    if (cJSON_IsArray(value)) {
        int n = cJSON_GetArraySize(value);
        if ((k = keyword(schema, "minItems")) && n < k->valueint)
            return false;
        if ((k = keyword(schema, "maxItems")) && n > k->valueint)
            return false;
        const cJSON *items = keyword(schema, "items"), *item;
        cJSON_ArrayForEach(item, value)
        {
            if (items && !schema_conforms(root, items, item))
                return false;
        }
    }
    if ((k = keyword(schema, "oneOf"))) {
        int matches = 0;
        const cJSON *option;
        cJSON_ArrayForEach(option, k) matches += schema_conforms(root, option, value);
        if (matches != 1)
            return false;
    }
    return !cJSON_IsObject(value) || conforms_object(root, schema, value);
}
