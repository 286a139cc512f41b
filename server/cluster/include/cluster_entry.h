/* One accepted change of a shared world as the stream holds it, or the world's whole state
 * (a snapshot: start-up, or a node that fell behind a trimmed stream). The cluster room moves
 * these as text and bytes; the world host gives them meaning. */
#ifndef SKYD_CLUSTER_ENTRY_H
#define SKYD_CLUSTER_ENTRY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define CLUSTER_ID_MAX 48

struct cluster_entry {
    struct cluster_entry *next;
    bool snapshot;           /* the whole world, not one change */
    char id[CLUSTER_ID_MAX]; /* the stream id ("0-0": none yet) */
    uint64_t revision;
    char *state;        /* the state's JSON text (malloc'd) */
    char *by;           /* who made the change (malloc'd, "" for a snapshot) */
    char *changed;      /* JSON Pointers of the changed fields, '\n' between them */
    unsigned char *map; /* the client weather map set with it, NULL: none */
    size_t map_length;
};

void cluster_entry_free(struct cluster_entry *entry);
/* Frees a whole list. */
void cluster_entry_free_list(struct cluster_entry *entry);

#endif
