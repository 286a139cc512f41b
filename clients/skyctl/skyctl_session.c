/* skyctl's connection: connect, hello, auth, requests matched to replies by id, and the
 * printing of server errors. */
#include "skyctl.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <string.h>

#include "sky_client.h"
#include "sky_client_json.h"

static const char *string_at(const cJSON *object, const char *name)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, name);
    return cJSON_IsString(item) ? item->valuestring : "";
}

void skyctl_print_error(const char *what, const cJSON *error)
{
    const char *code = string_at(error, "code");
    const cJSON *fields = cJSON_GetObjectItemCaseSensitive(error, "fields");
    if (cJSON_GetArraySize(fields) == 0) {
        fprintf(stderr, "skyctl: %s: %s [%s]\n", what, string_at(error, "message"), code);
        return;
    }
    const cJSON *field;
    cJSON_ArrayForEach(field, fields)
    {
        fprintf(stderr, "skyctl: %s: %s: %s [%s]\n", what, string_at(field, "pointer"),
                string_at(field, "reason"), string_at(field, "code"));
    }
    const cJSON *omitted = cJSON_GetObjectItemCaseSensitive(error, "fields_omitted");
    if (cJSON_IsNumber(omitted) && omitted->valuedouble > 0)
        fprintf(stderr, "skyctl: %s: and %.0f more\n", what, omitted->valuedouble);
}

static int connection_failure(struct skyctl_session *session, const char *what, const char *why)
{
    int code = sky_client_close_code(session->client);
    const char *reason = sky_client_close_reason(session->client);
    if (code && code != 1006)
        fprintf(stderr, "skyctl: %s: %s (closed by the server: %d %s)\n", what, why, code, reason);
    else
        fprintf(stderr, "skyctl: %s: %s\n", what, why);
    return SKYCTL_CONNECTION;
}

static int reply_of(struct skyctl_session *session, const char *what, long id, cJSON **reply)
{
    for (;;) {
        cJSON *msg = NULL;
        char err[320];
        int rc = sky_client_recv_json(session->client, NULL, session->timeout_ms, &msg, err,
                                      sizeof err);
        if (rc)
            return connection_failure(session, what, rc == 1 ? "no reply in time" : err);
        const cJSON *msg_id = cJSON_GetObjectItemCaseSensitive(msg, "id");
        bool frame = strcmp(string_at(msg, "type"), "frame") == 0;
        if (!frame && cJSON_IsNumber(msg_id) && msg_id->valuedouble == (double)id) {
            if (strcmp(string_at(msg, "type"), "error") == 0) {
                skyctl_print_error(what, msg);
                cJSON_Delete(msg);
                return SKYCTL_SERVER_ERROR;
            }
            *reply = msg;
            return SKYCTL_OK;
        }
        cJSON_Delete(msg);
    }
}

int skyctl_request(struct skyctl_session *session, const char *what, cJSON *msg, cJSON **reply)
{
    *reply = NULL;
    long id = session->next_id++;
    cJSON_DeleteItemFromObjectCaseSensitive(msg, "id");
    cJSON_AddNumberToObject(msg, "id", (double)id);
    int rc = sky_client_send_json(session->client, msg, session->timeout_ms);
    if (rc)
        return connection_failure(
            session, what, rc == 1 ? "could not send in time" : sky_client_error(session->client));
    return reply_of(session, what, id, reply);
}

int skyctl_connect(const struct skyctl_options *options, struct skyctl_session *session)
{
    memset(session, 0, sizeof *session);
    session->next_id = 1;
    session->timeout_ms = options->timeout_ms;
    char err[320];
    struct sky_client_tls tls = { .ca_file = options->ca_file, .insecure = options->insecure };
    bool wss = strncmp(options->url, "wss://", 6) == 0;
    if (wss && options->insecure)
        fprintf(stderr, "skyctl: warning: --insecure: the server's certificate is not checked; "
                        "anyone on the way can read and change this connection\n");
    session->client = sky_client_connect_tls(options->url, NULL, &tls, options->timeout_ms, err,
                                             sizeof err);
    if (!session->client) {
        fprintf(stderr, "skyctl: cannot connect to %s: %s\n", options->url, err);
        if (tls.certificate_rejected)
            fputs("skyctl: --ca-file FILE trusts a PEM certificate (e.g. the server's own), "
                  "--insecure skips the certificate check\n",
                  stderr);
        return SKYCTL_CONNECTION;
    }
    cJSON *hello = NULL;
    int rc = sky_client_recv_json(session->client, NULL, options->timeout_ms, &hello, err,
                                  sizeof err);
    if (rc || strcmp(string_at(hello, "type"), "hello") != 0) {
        if (!rc && strcmp(string_at(hello, "type"), "error") == 0)
            skyctl_print_error("connect", hello); /* e.g. limit_reached: too many clients */
        else
            connection_failure(session, "connect", rc ? err : "the server sent no hello");
        cJSON_Delete(hello);
        skyctl_disconnect(session);
        return rc || !hello ? SKYCTL_CONNECTION : SKYCTL_SERVER_ERROR;
    }
    cJSON_Delete(hello);
    if (!options->token)
        return SKYCTL_OK;
    cJSON *auth = cJSON_CreateObject();
    cJSON_AddStringToObject(auth, "type", "auth");
    cJSON_AddStringToObject(auth, "token", options->token);
    cJSON *reply = NULL;
    rc = skyctl_request(session, "auth", auth, &reply);
    cJSON_Delete(auth);
    cJSON_Delete(reply);
    if (rc)
        skyctl_disconnect(session);
    return rc;
}

void skyctl_disconnect(struct skyctl_session *session)
{
    sky_client_close(&session->client);
}
