// A C++17 program using missionlink.h: two partitions under the prefix given as the argument,
// one publishing progress, the other waking on it and taking it; every payload size the library
// knows is the struct's sizeof. Prints what it took; exits 0 when all is as expected
// (tests/c_partition.rs builds and runs it).
#include <cstdio>
#include <cstring>

#include "missionlink.h"

namespace {

bool ok(int32_t status, const char *what) {
    if (status == MISSIONLINK_OK) {
        return true;
    }
    char message[256];
    missionlink_last_error(message, sizeof message);
    std::fprintf(stderr, "%s: %s: %s\n", what, missionlink_status_name(status), message);
    return false;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s SERVICE_PREFIX\n", argv[0]);
        return 2;
    }
    const struct {
        missionlink_service service;
        size_t size;
    } sizes[] = {
        {MISSIONLINK_SERVICE_ID_LINK_UPLINK, sizeof(FramePayload)},
        {MISSIONLINK_SERVICE_ID_LINK_DOWNLINK, sizeof(FramePayload)},
        {MISSIONLINK_SERVICE_ID_MISSION_WAYPOINT_LIST, sizeof(WaypointListPayload)},
        {MISSIONLINK_SERVICE_ID_MISSION_AREA_LIST, sizeof(AreaListPayload)},
        {MISSIONLINK_SERVICE_ID_AUTOMATION_STATE, sizeof(AutomationStatePayload)},
        {MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS, sizeof(GuidanceProgressPayload)},
        {MISSIONLINK_SERVICE_ID_AUTOMATION_COMMAND, sizeof(AutomationCommandPayload)},
        {MISSIONLINK_SERVICE_ID_HEALTH_VOTING_MONITORING, sizeof(HeartbeatPayload)},
        {MISSIONLINK_SERVICE_ID_HEALTH_MISSION_DATA_HANDLING, sizeof(HeartbeatPayload)},
        {MISSIONLINK_SERVICE_ID_HEALTH_SYSTEM_AUTOMATION, sizeof(HeartbeatPayload)},
        {MISSIONLINK_SERVICE_ID_HEALTH_GUIDANCE, sizeof(HeartbeatPayload)},
    };
    for (const auto &s : sizes) {
        if (missionlink_payload_size(s.service) != s.size) {
            std::fprintf(stderr, "service %d: the library's size %zu, sizeof %zu\n",
                         static_cast<int>(s.service), missionlink_payload_size(s.service), s.size);
            return 1;
        }
    }

    missionlink_partition *guidance = nullptr;
    missionlink_partition *automation = nullptr;
    if (!ok(missionlink_partition_open("cpp-guidance", argv[1], MISSIONLINK_ROLE_GUIDANCE, 0,
                                       &guidance),
            "open guidance") ||
        !ok(missionlink_partition_open("cpp-automation", argv[1],
                                       MISSIONLINK_ROLE_SYSTEM_AUTOMATION, 0, &automation),
            "open automation") ||
        !ok(missionlink_publisher_open(guidance, MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS),
            "publisher") ||
        !ok(missionlink_subscriber_open(automation, MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS),
            "subscriber")) {
        return 1;
    }

    GuidanceProgressPayload sent{};
    sent.sequence = 1;
    sent.from = 1;
    sent.to = 2;
    sent.next = 3;
    sent.latitude_deg = 48.275;
    sent.longitude_deg = 11.645;
    if (!ok(missionlink_publish(guidance, MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS, &sent,
                                sizeof sent),
            "publish") ||
        !ok(missionlink_wait(automation, 5000000000ull), "wait")) {
        return 1;
    }
    GuidanceProgressPayload taken{};
    if (!ok(missionlink_take_latest(automation, MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS, &taken,
                                    sizeof taken),
            "take")) {
        return 1;
    }
    if (std::memcmp(&sent, &taken, sizeof sent) != 0) {
        std::fprintf(stderr, "taken differs from sent\n");
        return 1;
    }
    std::printf("took from-to-next %u %u %u at %.3f %.3f\n", taken.from, taken.to, taken.next,
                taken.latitude_deg, taken.longitude_deg);
    missionlink_partition_close(automation);
    missionlink_partition_close(guidance);
    return 0;
}
