/* A C program passing the library null pointers, wrong lengths, unknown services and a payload
 * that is no valid value: each call must return its error code (printed by name), never crash.
 * Exits 0 when every code is the expected one (tests/system/c_partition.rs runs it). */
#include <stdio.h>
#include <string.h>

#include "missionlink.h"

static int failures = 0;

static void expect(const char *what, int32_t got, int32_t wanted) {
    char message[256];
    missionlink_last_error(message, sizeof message);
    printf("%s: %s (%s)\n", what, missionlink_status_name(got), got < 0 ? message : "");
    if (got != wanted) {
        printf("  expected %s\n", missionlink_status_name(wanted));
        failures++;
    }
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s SERVICE_PREFIX\n", argv[0]);
        return 2;
    }
    const int progress = MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS;
    GuidanceProgressPayload p;
    memset(&p, 0, sizeof p);

    expect("open with a null out-pointer",
           missionlink_partition_open("c-bad", argv[1], MISSIONLINK_ROLE_GUIDANCE, 0, NULL),
           MISSIONLINK_ERROR_NULL_POINTER);
    missionlink_partition *partition = (missionlink_partition *)&p; /* overwritten with NULL */
    expect("open with a null node name",
           missionlink_partition_open(NULL, argv[1], MISSIONLINK_ROLE_GUIDANCE, 0, &partition),
           MISSIONLINK_ERROR_NULL_POINTER);
    expect("the handle of a failed open is null", partition == NULL ? 0 : -1, 0);
    expect("open with an unknown role",
           missionlink_partition_open("c-bad", argv[1], 17, 0, &partition),
           MISSIONLINK_ERROR_INVALID_ARGUMENT);
    expect("publish on a null partition", missionlink_publish(NULL, progress, &p, sizeof p),
           MISSIONLINK_ERROR_NULL_POINTER);
    expect("wait on a null partition", missionlink_wait(NULL, 0), MISSIONLINK_ERROR_NULL_POINTER);

    expect("open", missionlink_partition_open("c-bad", argv[1], MISSIONLINK_ROLE_GUIDANCE, 0,
                                              &partition),
           MISSIONLINK_OK);
    if (partition == NULL) {
        return 1;
    }
    expect("publish before the publisher is open",
           missionlink_publish(partition, progress, &p, sizeof p), MISSIONLINK_ERROR_NOT_OPEN);
    expect("publisher_open", missionlink_publisher_open(partition, progress), MISSIONLINK_OK);
    expect("subscriber_open", missionlink_subscriber_open(partition, progress), MISSIONLINK_OK);
    expect("publisher_open of an unknown service", missionlink_publisher_open(partition, 42),
           MISSIONLINK_ERROR_INVALID_ARGUMENT);
    expect("publish a null payload", missionlink_publish(partition, progress, NULL, sizeof p),
           MISSIONLINK_ERROR_NULL_POINTER);
    expect("publish a payload one byte short",
           missionlink_publish(partition, progress, &p, sizeof p - 1),
           MISSIONLINK_ERROR_WRONG_SIZE);
    expect("publish a heartbeat's size on progress",
           missionlink_publish(partition, progress, &p, sizeof(HeartbeatPayload)),
           MISSIONLINK_ERROR_WRONG_SIZE);
    unsigned char bytes[sizeof(GuidanceProgressPayload)];
    memcpy(bytes, &p, sizeof bytes);
    bytes[offsetof(GuidanceProgressPayload, on_ground)] = 7; /* a bool that is neither 0 nor 1 */
    expect("publish a bool of 7", missionlink_publish(partition, progress, bytes, sizeof bytes),
           MISSIONLINK_ERROR_INVALID_PAYLOAD);
    expect("take into a null payload", missionlink_take(partition, progress, NULL, sizeof p),
           MISSIONLINK_ERROR_NULL_POINTER);
    expect("take into a length of 0", missionlink_take(partition, progress, &p, 0),
           MISSIONLINK_ERROR_WRONG_SIZE);
    expect("nothing was published by the refused calls",
           missionlink_take(partition, progress, &p, sizeof p), MISSIONLINK_NO_SAMPLE);
    expect("heartbeat with a null next-due pointer", missionlink_heartbeat(partition, NULL),
           MISSIONLINK_OK);
    expect("the name of a code no function returns",
           strcmp(missionlink_status_name(12345), "MISSIONLINK_UNKNOWN_STATUS") == 0 ? 0 : -1, 0);
    missionlink_partition_close(partition);
    missionlink_partition_close(NULL);
    printf("%d unexpected\n", failures);
    return failures == 0 ? 0 : 1;
}
