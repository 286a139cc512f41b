/* The client messages' JSON Schema tests (test_message_schema.c), run by test_world_schema's
 * main with the path of protocol/PROTOCOL.md. */
#ifndef SKYD_TEST_MESSAGE_SCHEMA_H
#define SKYD_TEST_MESSAGE_SCHEMA_H

void test_message_schema(const char *protocol_md);

#endif
