/* A small JSON Schema (2020-12) validator for the keywords skyd's generated schemas use, written
 * independently of the generators (protocol/schema_json_schema.c, message_schema_json.c):
 * type, minimum, exclusiveMinimum, maximum, enum, const, format date-time, minLength,
 * maxLength, pattern (POSIX extended), items, minItems, maxItems, properties,
 * additionalProperties false, required, oneOf, dependentSchemas and "$ref" to "#/$defs/NAME".
 * Others are ignored. */
#ifndef SKYD_SCHEMA_VALIDATOR_H
#define SKYD_SCHEMA_VALIDATOR_H

#include <stdbool.h>

#include <cjson/cJSON.h>

/* Whether `value` conforms to `schema`, a subschema of `root` (where "$ref"s resolve). */
bool schema_conforms(const cJSON *root, const cJSON *schema, const cJSON *value);

#endif
