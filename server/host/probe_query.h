/* The physical queries of `skyd probe` and the protocol's `probe` message, answered through
 * the renderer's own LUTs and shading (the same code path as frames). */
#ifndef SKYD_PROBE_QUERY_H
#define SKYD_PROBE_QUERY_H

#include "messages.h"
#include "render_input.h"
#include "sky_renderer.h"

/* Fills *result for the query's quantity under the input state's atmosphere and sun
 * photometry. Returns 0 or -1. */
int probe_query_run(struct sky_renderer *renderer, const struct render_input *input,
                    const struct proto_msg_probe *query, struct proto_msg_probe_result *result);

#endif
