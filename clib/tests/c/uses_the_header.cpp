// A C++17 program using missionlink.h: every service number of the header is the library's (its
// payload's sizeof, its path), and every status (its name); then two partitions under the prefix
// given as the argument, one publishing progress, the other waking on it and taking it. Prints what it took; exits 0 when all is as expected
// (tests/system/c_partition.rs builds and runs it).
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
    // Each service number of this header is the library's: its payload's sizeof and its path.
    const struct {
        missionlink_service service;
        size_t size;
        const char *path;
    } services[] = {
        {MISSIONLINK_SERVICE_ID_LINK_UPLINK, sizeof(FramePayload),
         MISSIONLINK_SERVICE_LINK_UPLINK_PATH},
        {MISSIONLINK_SERVICE_ID_LINK_DOWNLINK, sizeof(FramePayload),
         MISSIONLINK_SERVICE_LINK_DOWNLINK_PATH},
        {MISSIONLINK_SERVICE_ID_MISSION_WAYPOINT_LIST, sizeof(WaypointListPayload),
         MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_PATH},
        {MISSIONLINK_SERVICE_ID_MISSION_AREA_LIST, sizeof(AreaListPayload),
         MISSIONLINK_SERVICE_MISSION_AREA_LIST_PATH},
        {MISSIONLINK_SERVICE_ID_AUTOMATION_STATE, sizeof(AutomationStatePayload),
         MISSIONLINK_SERVICE_AUTOMATION_STATE_PATH},
        {MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS, sizeof(GuidanceProgressPayload),
         MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_PATH},
        {MISSIONLINK_SERVICE_ID_AUTOMATION_COMMAND, sizeof(AutomationCommandPayload),
         MISSIONLINK_SERVICE_AUTOMATION_COMMAND_PATH},
        {MISSIONLINK_SERVICE_ID_HEALTH_VOTING_MONITORING, sizeof(HeartbeatPayload),
         MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_PATH},
        {MISSIONLINK_SERVICE_ID_HEALTH_MISSION_DATA_HANDLING, sizeof(HeartbeatPayload),
         MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_PATH},
        {MISSIONLINK_SERVICE_ID_HEALTH_SYSTEM_AUTOMATION, sizeof(HeartbeatPayload),
         MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_PATH},
        {MISSIONLINK_SERVICE_ID_HEALTH_GUIDANCE, sizeof(HeartbeatPayload),
         MISSIONLINK_SERVICE_HEALTH_GUIDANCE_PATH},
    };
    for (const auto &s : services) {
        const char *path = missionlink_service_path(s.service);
        if (missionlink_payload_size(s.service) != s.size || path == nullptr ||
            std::strcmp(path, s.path) != 0) {
            std::fprintf(stderr, "service %d: the library's size %zu and path %s, header's %zu %s\n",
                         static_cast<int>(s.service), missionlink_payload_size(s.service),
                         path ? path : "(null)", s.size, s.path);
            return 1;
        }
    }
    if (missionlink_service_path(11) != nullptr) {
        std::fprintf(stderr, "a path for service 11\n");
        return 1;
    }
    // Each status of this header is the library's: the library names it as the header spells it.
#define SAME_NAME(status)                                                                      \
    if (std::strcmp(missionlink_status_name(status), #status) != 0) {                          \
        std::fprintf(stderr, "%s is named %s\n", #status, missionlink_status_name(status));    \
        return 1;                                                                              \
    }
    SAME_NAME(MISSIONLINK_OK)
    SAME_NAME(MISSIONLINK_NO_SAMPLE)
    SAME_NAME(MISSIONLINK_ERROR_NULL_POINTER)
    SAME_NAME(MISSIONLINK_ERROR_WRONG_SIZE)
    SAME_NAME(MISSIONLINK_ERROR_INVALID_ARGUMENT)
    SAME_NAME(MISSIONLINK_ERROR_INVALID_PAYLOAD)
    SAME_NAME(MISSIONLINK_ERROR_NOT_OPEN)
    SAME_NAME(MISSIONLINK_ERROR_IPC)
    SAME_NAME(MISSIONLINK_ERROR_INTERNAL)
#undef SAME_NAME

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
