/*
 * foreign_sender.c: the sending end of the latency row `partition-foreign-sparse`
 * (benches/latency/main.rs): a partition in C on missionlink's C library, as voting-monitoring
 * would be in a rig that replaced it. It publishes a FramePayload on fcc/link/uplink with
 * CLOCK_MONOTONIC in origin_ns, sleeps in its WaitSet until mission data handling's reply on
 * fcc/link/downlink echoes that stamp, pauses for the sparse pace and sends the next; the
 * receiver, the bench's own process running mission data handling's loop, records the hop.
 *
 * Usage: foreign_sender SERVICE_PREFIX FRAMES PACE_NS (the bench builds and starts it).
 */
#define _POSIX_C_SOURCE 200809L

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "missionlink.h"

/* A side that hears nothing for this long gives up (the bench's TIMEOUT). */
#define TIMEOUT_NS 10000000000ull

static uint64_t monotonic_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

static int fail(const char *what, int32_t status) {
    char message[512];
    missionlink_last_error(message, sizeof message);
    fprintf(stderr, "foreign_sender: %s: %s: %s\n", what, missionlink_status_name(status), message);
    return 1;
}

int main(int argc, char **argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: %s SERVICE_PREFIX FRAMES PACE_NS\n", argv[0]);
        return 2;
    }
    unsigned long long frames = strtoull(argv[2], NULL, 10);
    unsigned long long pace_ns = strtoull(argv[3], NULL, 10);
    missionlink_partition *p = NULL;
    int32_t r = missionlink_partition_open("latency-foreign-sender", argv[1],
                                           MISSIONLINK_ROLE_VOTING_MONITORING, 0, &p);
    if (r != MISSIONLINK_OK) {
        return fail("open", r);
    }
    if ((r = missionlink_publisher_open(p, MISSIONLINK_SERVICE_ID_LINK_UPLINK)) != MISSIONLINK_OK ||
        (r = missionlink_subscriber_open(p, MISSIONLINK_SERVICE_ID_LINK_DOWNLINK)) !=
            MISSIONLINK_OK) {
        return fail("ports", r);
    }
    static FramePayload frame, reply;
    memset(&frame, 0, sizeof frame);
    frame.len = MISSIONLINK_MAX_FRAME_LEN;
    frame.link = MISSIONLINK_LINK_DIRECT;
    uint64_t next = monotonic_ns();
    for (unsigned long long i = 0; i < frames; i++) {
        /* The sparse pace: the next frame PACE_NS after the previous reply. */
        uint64_t now = monotonic_ns();
        if (next > now) {
            struct timespec pause = {(time_t)((next - now) / 1000000000ull),
                                     (long)((next - now) % 1000000000ull)};
            nanosleep(&pause, NULL);
        }
        frame.sequence = i + 1;
        frame.origin_ns = monotonic_ns();
        frame.published_ns = frame.origin_ns;
        if ((r = missionlink_publish(p, MISSIONLINK_SERVICE_ID_LINK_UPLINK, &frame,
                                     sizeof frame)) != MISSIONLINK_OK) {
            return fail("publish", r);
        }
        uint64_t deadline = frame.origin_ns + TIMEOUT_NS;
        for (;;) {
            r = missionlink_take(p, MISSIONLINK_SERVICE_ID_LINK_DOWNLINK, &reply, sizeof reply);
            if (r == MISSIONLINK_OK) {
                if (reply.origin_ns != frame.origin_ns) {
                    fprintf(stderr, "foreign_sender: a reply to another frame\n");
                    return 1;
                }
                break;
            }
            if (r != MISSIONLINK_NO_SAMPLE) {
                return fail("take", r);
            }
            if (monotonic_ns() > deadline) {
                fprintf(stderr, "foreign_sender: no reply for 10 s: peer gone\n");
                return 1;
            }
            if ((r = missionlink_wait(p, 1000000000ull)) != MISSIONLINK_OK) {
                return fail("wait", r);
            }
        }
        next = monotonic_ns() + pace_ns;
    }
    missionlink_partition_close(p);
    return 0;
}
