/*
 * missionlink.h: the C API of missionlink's C library (the crate clib/, libmissionlink_c.a and
 * libmissionlink_c.so), for a partition written in C or C++ that stands in for one of the FCC's
 * partitions in a hardware-in-the-loop rig (docs/hil.md).
 *
 * The payload structs, service paths and QoS are those of missionlink_contracts.h
 * (interfaces/c/), which this header includes: compile with -I interfaces/c -I clib/include.
 * The library opens each service with the contracts' QoS and notifies its event service after
 * every sample, as the Rust partitions do, so a C partition is heard as fast as a Rust one; it
 * waits in an iceoryx2 WaitSet on the events of what it subscribes to, as a Rust partition does
 * with the defaults of [ipc].
 *
 * Every function returns a missionlink_status (0 is success, positive is an outcome that is not
 * an error, negative an error) and never lets a failure of the library take the process down:
 * null pointers, payload sizes other than the struct's, unknown services or roles and payloads
 * whose bool fields are neither 0 nor 1 are refused with their codes. What cannot be checked:
 * a non-null pointer must point to as many bytes as the size passed with it, names must end
 * with NUL, a partition handle must come from missionlink_partition_open and not be closed, and
 * a partition is used by one thread at a time.
 *
 * Kept by hand with clib/src/lib.rs (the functions), clib/src/status.rs (the codes) and
 * clib/src/ports.rs (the service and role numbers: the order of FccService::ALL and
 * Partition::ALL); tests/system/c_partition.rs compiles it as C11 and C++17 with -Wall -Wextra -Werror
 * and runs programs against the library.
 */
#ifndef MISSIONLINK_H
#define MISSIONLINK_H

#include <stddef.h>
#include <stdint.h>

#include "missionlink_contracts.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a call did. */
typedef enum missionlink_status {
    MISSIONLINK_OK = 0,
    /* A take found no sample waiting (not an error). */
    MISSIONLINK_NO_SAMPLE = 1,
    /* A pointer argument was null. */
    MISSIONLINK_ERROR_NULL_POINTER = -1,
    /* A payload size other than sizeof the service's payload struct. */
    MISSIONLINK_ERROR_WRONG_SIZE = -2,
    /* An unknown service or role, a name that is not UTF-8 or that iceoryx2 does not take. */
    MISSIONLINK_ERROR_INVALID_ARGUMENT = -3,
    /* Payload bytes that are no valid value of the struct (a bool neither 0 nor 1). */
    MISSIONLINK_ERROR_INVALID_PAYLOAD = -4,
    /* Publish or take on a service without missionlink_publisher_open or _subscriber_open. */
    MISSIONLINK_ERROR_NOT_OPEN = -5,
    /* iceoryx2 refused (see missionlink_last_error). */
    MISSIONLINK_ERROR_IPC = -6,
    /* The library failed inside (see missionlink_last_error). */
    MISSIONLINK_ERROR_INTERNAL = -7
} missionlink_status;

/* The services (their paths and payload structs in missionlink_contracts.h). */
typedef enum missionlink_service {
    MISSIONLINK_SERVICE_ID_LINK_UPLINK = 0,                  /* FramePayload */
    MISSIONLINK_SERVICE_ID_LINK_DOWNLINK = 1,                /* FramePayload */
    MISSIONLINK_SERVICE_ID_MISSION_WAYPOINT_LIST = 2,        /* WaypointListPayload */
    MISSIONLINK_SERVICE_ID_MISSION_AREA_LIST = 3,            /* AreaListPayload */
    MISSIONLINK_SERVICE_ID_AUTOMATION_STATE = 4,             /* AutomationStatePayload */
    MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS = 5,            /* GuidanceProgressPayload */
    MISSIONLINK_SERVICE_ID_AUTOMATION_COMMAND = 6,           /* AutomationCommandPayload */
    MISSIONLINK_SERVICE_ID_HEALTH_VOTING_MONITORING = 7,     /* HeartbeatPayload */
    MISSIONLINK_SERVICE_ID_HEALTH_MISSION_DATA_HANDLING = 8, /* HeartbeatPayload */
    MISSIONLINK_SERVICE_ID_HEALTH_SYSTEM_AUTOMATION = 9,     /* HeartbeatPayload */
    MISSIONLINK_SERVICE_ID_HEALTH_GUIDANCE = 10              /* HeartbeatPayload */
} missionlink_service;

/* The role a partition fills: its heartbeat service. */
typedef enum missionlink_role {
    MISSIONLINK_ROLE_VOTING_MONITORING = 0,
    MISSIONLINK_ROLE_MISSION_DATA_HANDLING = 1,
    MISSIONLINK_ROLE_SYSTEM_AUTOMATION = 2,
    MISSIONLINK_ROLE_GUIDANCE = 3
} missionlink_role;

/* A partition: its iceoryx2 node, heartbeat and ports. Opaque. */
typedef struct missionlink_partition missionlink_partition;

/* Opens the node node_name under service_prefix (MISSIONLINK_DEFAULT_SERVICE_PREFIX, or the
 * FCC's [ipc] service_prefix), removing what dead nodes left; opens the heartbeat of role, beating every heartbeat_period_ns (0: MISSIONLINK_DEFAULT_HEARTBEAT_PERIOD_MS;
 * at most the FCC's [health] period_ms). *partition is the handle, or NULL on failure. */
int32_t missionlink_partition_open(const char *node_name, const char *service_prefix,
                                   int32_t role, uint64_t heartbeat_period_ns,
                                   missionlink_partition **partition);

/* Closes the partition and its ports; NULL does nothing. The handle is not used again. */
void missionlink_partition_close(missionlink_partition *partition);

/* Opens the publisher of service (a missionlink_service); once is enough. */
int32_t missionlink_publisher_open(missionlink_partition *partition, int32_t service);

/* Opens the subscriber of service; its samples end missionlink_wait. */
int32_t missionlink_subscriber_open(missionlink_partition *partition, int32_t service);

/* Publishes the payload struct at payload (size: its sizeof) and wakes the subscribers. */
int32_t missionlink_publish(missionlink_partition *partition, int32_t service,
                            const void *payload, size_t size);

/* Copies the oldest waiting sample into payload: MISSIONLINK_OK or MISSIONLINK_NO_SAMPLE. */
int32_t missionlink_take(missionlink_partition *partition, int32_t service, void *payload,
                         size_t size);

/* Copies the newest waiting sample into payload, dropping older ones: MISSIONLINK_OK or
 * MISSIONLINK_NO_SAMPLE (the state services, where only the latest matters). */
int32_t missionlink_take_latest(missionlink_partition *partition, int32_t service,
                                void *payload, size_t size);

/* Sleeps until a publisher of a service the partition subscribes to notifies it, or timeout_ns
 * passes; returns at once while a subscribed service has a sample waiting (take it). A signal
 * ends the wait early. */
int32_t missionlink_wait(missionlink_partition *partition, uint64_t timeout_ns);

/* Sends the role's heartbeat if one is due (the first at once); *next_due_ns (unless NULL) is
 * the time until the next one. Call it from the partition's loop, never from a thread of its
 * own: a loop that hangs must fall silent. */
int32_t missionlink_heartbeat(missionlink_partition *partition, uint64_t *next_due_ns);

/* sizeof the payload struct of service, 0 for an unknown service. */
size_t missionlink_payload_size(int32_t service);

/* The path of service under the prefix ("fcc/guidance/progress", as the contracts header's
 * MISSIONLINK_SERVICE_*_PATH), a static string; NULL for an unknown service. */
const char *missionlink_service_path(int32_t service);

/* The name of a status ("MISSIONLINK_ERROR_WRONG_SIZE"), a static string. */
const char *missionlink_status_name(int32_t status);

/* Copies the calling thread's last error message into buffer (cut to size - 1 bytes,
 * NUL-terminated) and returns its full length, as snprintf does. */
size_t missionlink_last_error(char *buffer, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* MISSIONLINK_H */
