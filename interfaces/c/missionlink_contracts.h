/*
 * missionlink_contracts.h: the iceoryx2 contracts between the FCC partitions for C (and C++),
 * the same payloads as interfaces/src/contracts.rs and the wire newtypes of
 * interfaces/src/wire (docs/design.md, "Contracts between partitions"), so that a partition written
 * in C opens the same services as the Rust ones.
 *
 * Hand-written, kept in step with the Rust types by interfaces/tests/contracts_layout.rs: it
 * parses this header (struct and field names, every MISSIONLINK_ name), compiles a program
 * against it and compares every size, alignment and field offset, every type name, service
 * path, QoS number, capacity and enumeration value with Rust's and Python's. Change the Rust
 * types, this header and interfaces/python/missionlink_contracts.py together.
 *
 * Opening a service from C (iceoryx2's C API): the payload type details are the type name
 * below (MISSIONLINK_<TYPE>_TYPE_NAME), sizeof and alignof of the struct, as
 *
 *     iox2_service_builder_pub_sub_set_payload_type_details(
 *         &builder, iox2_type_variant_FIXED_SIZE,
 *         MISSIONLINK_WAYPOINT_LIST_PAYLOAD_TYPE_NAME,
 *         strlen(MISSIONLINK_WAYPOINT_LIST_PAYLOAD_TYPE_NAME),
 *         sizeof(WaypointListPayload), alignof(WaypointListPayload));
 *
 * with no user header, and the QoS of the service (MISSIONLINK_SERVICE_<NAME>_*): history
 * size, subscriber buffer size, publishers, subscribers, safe overflow. The full service name
 * is "<prefix>/<path>" (default prefix MISSIONLINK_DEFAULT_SERVICE_PREFIX). Each service has an
 * event service of the same name, opened with max notifiers = the service's max publishers and
 * max listeners = its max subscribers; a publisher notifies it after every sample.
 *
 * Enumerations cross shared memory as uint8_t (the enums below name the values): a byte
 * written by another process may hold anything, so a reader treats an unknown value as
 * unknown. Optional enumeration bytes hold MISSIONLINK_ABSENT when absent. Every "reserved"
 * field is written as zero. No structure has padding: the bytes alignment would add are
 * reserved fields of their own, so a structure set to zero (memset, or = {0}) and then filled
 * in has every byte written, as the Rust partitions write theirs (the bridge sends the bytes as
 * they lie across hosts, ICD §14).
 */
#ifndef MISSIONLINK_CONTRACTS_H
#define MISSIONLINK_CONTRACTS_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Version of the payload layouts; part of every type name. */
#define MISSIONLINK_CONTRACT_VERSION 5
/* Service-name prefix used when none is configured. */
#define MISSIONLINK_DEFAULT_SERVICE_PREFIX "missionlink"
/* Marks an optional enumeration byte as absent. */
#define MISSIONLINK_ABSENT 0xff
/* The period partitions beat at when the configuration does not say (HeartbeatPayload). */
#define MISSIONLINK_DEFAULT_HEARTBEAT_PERIOD_MS 100

/* Capacities (interfaces/src/capacity.rs, and the wire layer's largest frame). */
#define MISSIONLINK_MAX_WAYPOINTS 256
#define MISSIONLINK_MAX_AREAS 11
#define MISSIONLINK_MAX_NO_FLY_ZONES 10
#define MISSIONLINK_MAX_POLYGON_VERTICES 60
#define MISSIONLINK_MIN_POLYGON_VERTICES 3
#define MISSIONLINK_MAX_FRAME_LEN 548

/* The services, by the path under the prefix, with their QoS (FccService::qos()); the event
 * service of the same name allows MAX_LISTENERS listeners (Qos::max_listeners). */

/* Voted uplink frames (FramePayload), voting-monitoring to mission-data-handling. */
#define MISSIONLINK_SERVICE_LINK_UPLINK_PATH "fcc/link/uplink"
#define MISSIONLINK_SERVICE_LINK_UPLINK_HISTORY_SIZE 0
#define MISSIONLINK_SERVICE_LINK_UPLINK_SUBSCRIBER_MAX_BUFFER_SIZE 256
#define MISSIONLINK_SERVICE_LINK_UPLINK_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_LINK_UPLINK_MAX_SUBSCRIBERS 4
#define MISSIONLINK_SERVICE_LINK_UPLINK_MAX_LISTENERS 8
#define MISSIONLINK_SERVICE_LINK_UPLINK_SAFE_OVERFLOW 0

/* Downlink frames (FramePayload), mission-data-handling to voting-monitoring. */
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_PATH "fcc/link/downlink"
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_HISTORY_SIZE 0
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_SUBSCRIBER_MAX_BUFFER_SIZE 256
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_MAX_SUBSCRIBERS 4
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_MAX_LISTENERS 8
#define MISSIONLINK_SERVICE_LINK_DOWNLINK_SAFE_OVERFLOW 0

/* The active waypoint list (WaypointListPayload), history 1. */
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_PATH "fcc/mission/waypoint-list"
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_MISSION_WAYPOINT_LIST_SAFE_OVERFLOW 1

/* The active area list (AreaListPayload), history 1. */
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_PATH "fcc/mission/area-list"
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_MISSION_AREA_LIST_SAFE_OVERFLOW 1

/* Flight phase and active functions (AutomationStatePayload), history 1. */
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_PATH "fcc/automation/state"
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_AUTOMATION_STATE_SAFE_OVERFLOW 1

/* FROM / TO / NEXT and position (GuidanceProgressPayload), history 1. */
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_PATH "fcc/guidance/progress"
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_GUIDANCE_PROGRESS_SAFE_OVERFLOW 1

/* #50000 commands accepted by mission data handling (AutomationCommandPayload), a queue. */
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_PATH "fcc/automation/command"
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_HISTORY_SIZE 0
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_SUBSCRIBER_MAX_BUFFER_SIZE 256
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_MAX_SUBSCRIBERS 4
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_MAX_LISTENERS 8
#define MISSIONLINK_SERVICE_AUTOMATION_COMMAND_SAFE_OVERFLOW 0

/* The partitions (Partition): each by its role, which the services named after a partition
 * carry (fcc/health/<role>, whatever fills the role: a partition in C beats on its role's
 * service), the Rust binary that fills it (what `fcc --without` takes to leave it out for a
 * replacement), and what its fence allows beyond every partition's loop: LINKS, it owns the UDP
 * links (inet sockets); STATE, it writes the state directory. */
#define MISSIONLINK_PARTITION_VOTING_MONITORING_ROLE "voting-monitoring"
#define MISSIONLINK_PARTITION_VOTING_MONITORING_BINARY "voting-monitoring"
#define MISSIONLINK_PARTITION_VOTING_MONITORING_LINKS 1
#define MISSIONLINK_PARTITION_VOTING_MONITORING_STATE 1

#define MISSIONLINK_PARTITION_MISSION_DATA_HANDLING_ROLE "mission-data-handling"
#define MISSIONLINK_PARTITION_MISSION_DATA_HANDLING_BINARY "mission-data-handling"
#define MISSIONLINK_PARTITION_MISSION_DATA_HANDLING_LINKS 0
#define MISSIONLINK_PARTITION_MISSION_DATA_HANDLING_STATE 1

#define MISSIONLINK_PARTITION_SYSTEM_AUTOMATION_ROLE "system-automation"
#define MISSIONLINK_PARTITION_SYSTEM_AUTOMATION_BINARY "system-automation"
#define MISSIONLINK_PARTITION_SYSTEM_AUTOMATION_LINKS 0
#define MISSIONLINK_PARTITION_SYSTEM_AUTOMATION_STATE 0

#define MISSIONLINK_PARTITION_GUIDANCE_ROLE "guidance"
#define MISSIONLINK_PARTITION_GUIDANCE_BINARY "guidance-stub"
#define MISSIONLINK_PARTITION_GUIDANCE_LINKS 0
#define MISSIONLINK_PARTITION_GUIDANCE_STATE 0

/* Heartbeats (HeartbeatPayload), one service per partition role, history 1. */
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_PATH "fcc/health/" MISSIONLINK_PARTITION_VOTING_MONITORING_ROLE
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_HEALTH_VOTING_MONITORING_SAFE_OVERFLOW 1

#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_PATH "fcc/health/" MISSIONLINK_PARTITION_MISSION_DATA_HANDLING_ROLE
#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_HEALTH_MISSION_DATA_HANDLING_SAFE_OVERFLOW 1

#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_PATH "fcc/health/" MISSIONLINK_PARTITION_SYSTEM_AUTOMATION_ROLE
#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_HEALTH_SYSTEM_AUTOMATION_SAFE_OVERFLOW 1

#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_PATH "fcc/health/" MISSIONLINK_PARTITION_GUIDANCE_ROLE
#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_HISTORY_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_SUBSCRIBER_MAX_BUFFER_SIZE 1
#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_MAX_PUBLISHERS 2
#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_MAX_SUBSCRIBERS 8
#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_MAX_LISTENERS 16
#define MISSIONLINK_SERVICE_HEALTH_GUIDANCE_SAFE_OVERFLOW 1

/* Enumerations (their bytes in the payloads). */

/* The link a frame arrived on or leaves by (FramePayload.link). */
enum Link {
    MISSIONLINK_LINK_DIRECT = 0,
    MISSIONLINK_LINK_LTE = 1,
    MISSIONLINK_LINK_BOTH = 2
};

/* Flight phases of system automation (AutomationStatePayload.flight_phase). */
enum FlightPhase {
    MISSIONLINK_FLIGHT_PHASE_ON_GROUND = 0,
    MISSIONLINK_FLIGHT_PHASE_TAKE_OFF = 1,
    MISSIONLINK_FLIGHT_PHASE_CRUISE = 2,
    MISSIONLINK_FLIGHT_PHASE_LANDING = 3,
    MISSIONLINK_FLIGHT_PHASE_LANDED = 4
};

/* #50000 commands (AutomationCommandPayload.command). */
enum ExecuteCommand {
    MISSIONLINK_EXECUTE_COMMAND_EXECUTE = 1,
    MISSIONLINK_EXECUTE_COMMAND_RETURN_TO_HOME = 2,
    MISSIONLINK_EXECUTE_COMMAND_LAND = 3,
    MISSIONLINK_EXECUTE_COMMAND_ACTIVATE_STAGED = 4
};

/* Altitude Type (WaypointEntry.altitude_type, AreaAltitudes.altitude_type). */
enum AltitudeType {
    MISSIONLINK_ALTITUDE_TYPE_PRESSURE = 0,
    MISSIONLINK_ALTITUDE_TYPE_BARO = 1,
    MISSIONLINK_ALTITUDE_TYPE_AGL = 2,
    MISSIONLINK_ALTITUDE_TYPE_WGS84 = 3
};

/* Speed Type (WaypointEntry.speed_type). */
enum SpeedType {
    MISSIONLINK_SPEED_TYPE_INDICATED_AIRSPEED = 0,
    MISSIONLINK_SPEED_TYPE_TRUE_AIRSPEED = 1,
    MISSIONLINK_SPEED_TYPE_GROUND_SPEED = 2
};

/* Turn Type (WaypointEntry.turn_type). */
enum TurnType {
    MISSIONLINK_TURN_TYPE_FLY_BY = 0,
    MISSIONLINK_TURN_TYPE_FLY_OVER = 1
};

/* Leg type of the leg that ends at a waypoint (WaypointEntry.leg_type). */
enum LegType {
    MISSIONLINK_LEG_TYPE_TRACK_TO_FIX = 0,
    MISSIONLINK_LEG_TYPE_RADIUS_TO_FIX = 1
};

/* Turn direction of a radius-to-fix leg (WaypointEntry.rf_turn_direction). */
enum TurnDirection {
    MISSIONLINK_TURN_DIRECTION_CLOCKWISE = 0,
    MISSIONLINK_TURN_DIRECTION_COUNTER_CLOCKWISE = 1
};

/* The iceoryx2 type names of the payloads. */
#define MISSIONLINK_FRAME_PAYLOAD_TYPE_NAME "missionlink::FramePayload/v5"
#define MISSIONLINK_WAYPOINT_ENTRY_TYPE_NAME "missionlink::WaypointEntry/v5"
#define MISSIONLINK_WAYPOINT_LIST_PAYLOAD_TYPE_NAME "missionlink::WaypointListPayload/v5"
#define MISSIONLINK_AREA_ALTITUDES_TYPE_NAME "missionlink::AreaAltitudes/v5"
#define MISSIONLINK_POLYGON_AREA_TYPE_NAME "missionlink::PolygonArea/v5"
#define MISSIONLINK_CIRCLE_AREA_TYPE_NAME "missionlink::CircleArea/v5"
#define MISSIONLINK_AREA_LIST_PAYLOAD_TYPE_NAME "missionlink::AreaListPayload/v5"
#define MISSIONLINK_AUTOMATION_STATE_PAYLOAD_TYPE_NAME "missionlink::AutomationStatePayload/v5"
#define MISSIONLINK_AUTOMATION_COMMAND_PAYLOAD_TYPE_NAME "missionlink::AutomationCommandPayload/v5"
#define MISSIONLINK_HEARTBEAT_PAYLOAD_TYPE_NAME "missionlink::HeartbeatPayload/v5"
#define MISSIONLINK_GUIDANCE_PROGRESS_PAYLOAD_TYPE_NAME "missionlink::GuidanceProgressPayload/v5"

/* The wire newtypes: raw values in the ICD's units (ICD §3). */

/* BAM4 angle: degrees = raw * 180 / 2^31. */
typedef struct Angle {
    int32_t raw;
} Angle;

/* ALT3 altitude or height: metres = raw * 0.02 (24 bits used, sign-extended). */
typedef struct Altitude {
    int32_t raw;
} Altitude;

/* SPD2 speed: m/s = raw * 0.5. */
typedef struct Speed {
    uint16_t raw;
} Speed;

/* Safety offset: metres = raw * 0.1. */
typedef struct SafetyOffset {
    uint16_t raw;
} SafetyOffset;

/* A latitude and longitude on WGS-84. */
typedef struct GeoPoint {
    Angle latitude;
    Angle longitude;
} GeoPoint;

/* The payloads. */

/* fcc/link/uplink, fcc/link/downlink: a STANAG frame as opaque bytes plus metadata. */
typedef struct FramePayload {
    uint64_t origin_ns;    /* CLOCK_MONOTONIC ns when the frame entered or was produced */
    uint64_t published_ns; /* CLOCK_MONOTONIC ns when published on this service */
    uint64_t sequence;     /* counts frames per publisher, from 1 */
    uint16_t len;          /* bytes used of bytes */
    uint8_t link;          /* enum Link */
    uint8_t reserved[5];
    uint8_t bytes[MISSIONLINK_MAX_FRAME_LEN];
    uint8_t reserved_tail[4];
} FramePayload;

/* One waypoint of the assembled list, in flight-plan order. */
typedef struct WaypointEntry {
    uint16_t number;
    uint16_t next;              /* 0 on the last */
    GeoPoint position;
    Altitude altitude;
    Speed speed;
    uint8_t altitude_type;      /* enum AltitudeType or MISSIONLINK_ABSENT */
    uint8_t speed_type;         /* enum SpeedType or MISSIONLINK_ABSENT */
    uint8_t turn_type;          /* enum TurnType */
    uint8_t leg_type;           /* enum LegType of the leg that ends here */
    uint8_t rf_turn_direction;  /* enum TurnDirection, or MISSIONLINK_ABSENT for track-to-fix */
    uint8_t reserved;
    GeoPoint rf_centre;         /* centre of a radius-to-fix leg */
} WaypointEntry;

/* fcc/mission/waypoint-list: the active waypoint list. */
typedef struct WaypointListPayload {
    uint64_t generation;        /* activations of a new list, from 1; 0: no mission */
    uint64_t activation;        /* use only with the area list of the same activation */
    Altitude take_off_height;
    uint16_t count;             /* waypoints used */
    uint16_t initial_waypoint;
    bool bidirectional;
    uint8_t reserved0;
    Speed planning_wind;        /* wind the mission was checked in (#13001 field 5); 0: calm */
    uint8_t reserved[4];
    WaypointEntry waypoints[MISSIONLINK_MAX_WAYPOINTS];
} WaypointListPayload;

/* Altitude bounds of an area, each optional. */
typedef struct AreaAltitudes {
    Altitude lower;
    Altitude upper;
    bool has_lower;
    bool has_upper;
    uint8_t altitude_type;      /* enum AltitudeType or MISSIONLINK_ABSENT */
    uint8_t reserved;
} AreaAltitudes;

/* A polygonal area: the fly-zone or a polygonal no-fly-zone. */
typedef struct PolygonArea {
    uint16_t area_id;
    uint8_t vertex_count;       /* 3..=60 */
    uint8_t reserved;
    AreaAltitudes altitudes;
    GeoPoint vertices[MISSIONLINK_MAX_POLYGON_VERTICES];
} PolygonArea;

/* A circular no-fly-zone. */
typedef struct CircleArea {
    uint16_t area_id;
    uint8_t reserved[2];
    AreaAltitudes altitudes;
    GeoPoint centre;
    GeoPoint border;            /* a point on the border */
} CircleArea;

/* fcc/mission/area-list: the active area list. */
typedef struct AreaListPayload {
    uint64_t generation;        /* from 1; 0: no area list */
    uint64_t activation;        /* use only with the waypoint list of the same activation */
    SafetyOffset safety_offset;
    uint8_t no_fly_polygon_count;
    uint8_t no_fly_circle_count;
    uint8_t reserved[4];
    PolygonArea fly_zone;
    PolygonArea no_fly_polygons[MISSIONLINK_MAX_NO_FLY_ZONES];
    CircleArea no_fly_circles[MISSIONLINK_MAX_NO_FLY_ZONES];
} AreaListPayload;

/* fcc/automation/state: the flight phase and which functions are active. */
typedef struct AutomationStatePayload {
    uint64_t sequence;
    uint64_t changed_ns;
    uint64_t flown_waypoint_list;        /* generation flown, 0 for none */
    uint8_t flight_phase;                /* enum FlightPhase */
    bool trajectory_generation_active;
    bool route_reversed;                 /* return to home */
    uint8_t reserved0;
    uint16_t land_at;                    /* land at this waypoint, 0 for the last */
    bool guidance_alive;
    uint8_t reserved[9];
} AutomationStatePayload;

/* fcc/automation/command: a #50000 command that mission data handling accepted. */
typedef struct AutomationCommandPayload {
    uint64_t sequence;
    uint64_t accepted_ns;
    uint8_t command;            /* enum ExecuteCommand */
    uint8_t reserved[7];
} AutomationCommandPayload;

/* fcc/health/<partition>: a partition shows it is alive, once per period. */
typedef struct HeartbeatPayload {
    uint64_t sequence;          /* from 1 */
    uint64_t time_ns;           /* CLOCK_MONOTONIC ns when sent */
    uint64_t period_ns;         /* the period it beats at, above 0 */
    uint32_t pid;
    uint8_t reserved[4];
} HeartbeatPayload;

/* fcc/guidance/progress: FROM, TO and NEXT, the position and the attitude, from guidance.
 * The four floats are NaN where guidance does not know one (before anything is flown, all
 * four); a reader takes any value that is not finite as not known. */
typedef struct GuidanceProgressPayload {
    uint64_t sequence;
    uint64_t time_ns;
    uint64_t waypoint_list;     /* generation flown, 0 for none */
    double latitude_deg;
    double longitude_deg;
    double altitude_m;
    double ground_speed_mps;
    uint16_t from;              /* 0: none */
    uint16_t to;                /* 0: none */
    uint16_t next;              /* 0: none */
    uint16_t in_no_fly_zone;    /* area ID, 0 for none */
    bool inside_fly_zone;
    bool trajectory_generation_active;
    bool climb_complete;
    bool route_complete;
    bool on_ground;
    uint8_t reserved[3];
    float heading_deg;          /* true heading (nose), deg clockwise from north, 0..360 */
    float roll_deg;             /* bank, deg, positive right wing down */
    float pitch_deg;            /* deg, positive nose up */
    float climb_rate_mps;       /* vertical speed, m/s, positive up */
} GuidanceProgressPayload;

#ifdef __cplusplus
}
#endif

#endif /* MISSIONLINK_CONTRACTS_H */
