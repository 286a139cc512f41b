/* The world state's field table (world_fields.c), the rows of proto_world_schema(), indexed by
 * a compiled patch's field numbers (world_state.c). Internal to protocol/. */
#ifndef SKYD_WORLD_FIELDS_H
#define SKYD_WORLD_FIELDS_H

#include <stddef.h>

#include "field_schema.h"
#include "world_state.h"

extern const struct proto_field_desc proto_world_field_table[];
extern const size_t proto_world_field_count;

#endif
