/*
 * guidance.c: the guidance partition in C, standing in for the Rust guidance stub
 * (partitions/src/guidance_stub.rs) as the Python guidance does, through missionlink's C library
 * (clib/include/missionlink.h): what a hardware-in-the-loop rig's own guidance in C would do
 * (docs/hil.md).
 *
 * It subscribes to the active waypoint and area lists (flown only as a pair of one activation,
 * as ipc::ListPairing takes them) and to the automation state, flies the list through the flight
 * phases of system automation at a configured speed, time-scaled for demos, and publishes FROM /
 * TO / NEXT, the position and the flags system automation moves on (climb complete, route
 * complete, on the ground) on fcc/guidance/progress, as the contract says
 * (missionlink_contracts.h, GuidanceProgressPayload). It beats on fcc/health/guidance from its
 * loop and sleeps on its doorbell until an input arrives or its next step is due.
 *
 * The route logic is the Rust model's (services/flight/src/guidance/route.rs): FROM 0 and TO the first
 * waypoint at take-off, each waypoint reached makes it FROM and the one after it TO; NEXT is
 * the waypoint after TO; return to home (route_reversed, on bidirectional lists) flies the route
 * backwards from TO; land-at ends it at that waypoint when still ahead; a new list in the air
 * waits until automation names its generation. The kinematics are simpler, on purpose: legs are
 * great circles on a sphere flown straight at --speed-mps (radius-to-fix legs too), every
 * waypoint is flown over (no fly-by arcs, which only switch FROM-TO-NEXT a little earlier), no
 * wind, and the altitude goes linearly to the TO waypoint's. The climb and the descent are
 * vertical at the configured rates, as in the Rust model.
 *
 * Usage (the FCC started without its stub: fcc --without guidance-stub):
 *
 *     cc -std=c11 -O2 -I interfaces/c -I clib/include clib/partitions/guidance.c \
 *         target/release/libmissionlink_c.a -lm -lpthread -ldl -o guidance-c
 *     ./guidance-c --service-prefix missionlink --time-scale 20
 *
 * Logs go to stderr; SIGTERM or SIGINT ends it cleanly (exit status 0).
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "missionlink.h"

/* Pi (M_PI is not standard C). */
#define PI 3.14159265358979323846
/* Mean Earth radius, metres (the sphere the legs are flown on). */
#define EARTH_RADIUS_M 6371008.8
/* Longest sub-step of the integration, simulated seconds (as the Rust model). */
#define MAX_SUB_STEP_S 0.05
/* Paths ends handled within one sub-step at most. */
#define MAX_LEGS_PER_SUB_STEP 8
/* A waypoint closer than this is reached, metres. */
#define REACHED_M 0.01
/* Climb and descent end this close to their target altitude, metres. */
#define ALTITUDE_EPSILON_M 1e-6
/* Progress is published on every change and at least this often, nanoseconds. */
#define REPUBLISH_NS 1000000000ull
/* The position is logged this often, nanoseconds. */
#define POSITION_LOG_NS 5000000000ull

static volatile sig_atomic_t stop_requested = 0;

static void on_signal(int signal_number) {
    (void)signal_number;
    stop_requested = 1;
}

struct config {
    const char *service_prefix;
    double time_scale;
    double start_latitude_deg;
    double start_longitude_deg;
    double climb_rate_mps;
    double descent_rate_mps;
    double speed_mps;
    long update_interval_ms;
    long heartbeat_period_ms;
};

/* The list flown and where the aircraft is on it. Indices are into list.waypoints; -1: none. */
struct guidance {
    struct config config;
    WaypointListPayload list;
    WaypointListPayload pending; /* a newer list received in the air */
    bool has_pending;
    AreaListPayload areas;
    AutomationStatePayload automation;
    double latitude_deg, longitude_deg, altitude_m;
    double ground_speed_mps, climb_rate_mps, heading_deg;
    bool heading_known;
    bool climb_complete;
    bool started, reversed, complete;
    uint16_t from;
    int to;
    uint64_t sequence;
    uint64_t last_step_ns;
    bool stepped;
};

/* The lists as ipc::ListPairing pairs them: the newest of each kept, released together only
 * when of one activation and newer than the pair released before. */
struct pairing {
    WaypointListPayload waypoints;
    AreaListPayload areas;
    bool has_waypoints, has_areas, has_released;
    uint64_t released;
};

static uint64_t monotonic_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (uint64_t)t.tv_sec * 1000000000ull + (uint64_t)t.tv_nsec;
}

static void log_line(const char *format, ...) {
    va_list args;
    va_start(args, format);
    fprintf(stderr, "guidance-c: ");
    vfprintf(stderr, format, args);
    fprintf(stderr, "\n");
    fflush(stderr);
    va_end(args);
}

/* --- the wire units and the sphere ------------------------------------------------------- */

static double radians(double d) { return d * PI / 180.0; }
static double degrees(double r) { return r * 180.0 / PI; }
static double angle_deg(Angle a) { return (double)a.raw * 180.0 / 2147483648.0; }
static double altitude_metres(Altitude a) { return (double)a.raw * 0.02; }

static double distance_m(double lat1, double lon1, double lat2, double lon2) {
    double p1 = radians(lat1), p2 = radians(lat2);
    double dp = p2 - p1, dl = radians(lon2 - lon1);
    double a = sin(dp / 2) * sin(dp / 2) + cos(p1) * cos(p2) * sin(dl / 2) * sin(dl / 2);
    return 2 * EARTH_RADIUS_M * atan2(sqrt(a), sqrt(1 - a));
}

static double bearing_deg(double lat1, double lon1, double lat2, double lon2) {
    double p1 = radians(lat1), p2 = radians(lat2), dl = radians(lon2 - lon1);
    double y = sin(dl) * cos(p2);
    double x = cos(p1) * sin(p2) - sin(p1) * cos(p2) * cos(dl);
    double b = fmod(degrees(atan2(y, x)) + 360.0, 360.0);
    return b;
}

static void destination(double lat, double lon, double bearing, double distance, double *lat2,
                        double *lon2) {
    double d = distance / EARTH_RADIUS_M, b = radians(bearing), p1 = radians(lat);
    double p2 = asin(sin(p1) * cos(d) + cos(p1) * sin(d) * cos(b));
    double l2 = radians(lon) + atan2(sin(b) * sin(d) * cos(p1), cos(d) - sin(p1) * sin(p2));
    *lat2 = degrees(p2);
    *lon2 = fmod(degrees(l2) + 540.0, 360.0) - 180.0;
}

/* --- the zones (information only: nothing decides on them) ------------------------------- */

static bool polygon_contains(const PolygonArea *p, double lat, double lon) {
    int n = p->vertex_count;
    if (n < MISSIONLINK_MIN_POLYGON_VERTICES || n > MISSIONLINK_MAX_POLYGON_VERTICES) {
        return false;
    }
    bool inside = false;
    for (int i = 0, j = n - 1; i < n; j = i++) {
        double yi = angle_deg(p->vertices[i].latitude), xi = angle_deg(p->vertices[i].longitude);
        double yj = angle_deg(p->vertices[j].latitude), xj = angle_deg(p->vertices[j].longitude);
        if ((yi > lat) != (yj > lat) && lon < (xj - xi) * (lat - yi) / (yj - yi) + xi) {
            inside = !inside;
        }
    }
    return inside;
}

static void zone_status(const struct guidance *g, bool *inside_fly_zone, uint16_t *no_fly_zone) {
    const AreaListPayload *a = &g->areas;
    double lat = g->latitude_deg, lon = g->longitude_deg;
    *inside_fly_zone = a->generation != 0 && polygon_contains(&a->fly_zone, lat, lon);
    *no_fly_zone = 0;
    for (int i = 0; i < a->no_fly_polygon_count && i < MISSIONLINK_MAX_NO_FLY_ZONES; i++) {
        if (polygon_contains(&a->no_fly_polygons[i], lat, lon)) {
            *no_fly_zone = a->no_fly_polygons[i].area_id;
            return;
        }
    }
    for (int i = 0; i < a->no_fly_circle_count && i < MISSIONLINK_MAX_NO_FLY_ZONES; i++) {
        const CircleArea *c = &a->no_fly_circles[i];
        double clat = angle_deg(c->centre.latitude), clon = angle_deg(c->centre.longitude);
        double radius = distance_m(clat, clon, angle_deg(c->border.latitude),
                                   angle_deg(c->border.longitude));
        if (distance_m(clat, clon, lat, lon) <= radius) {
            *no_fly_zone = c->area_id;
            return;
        }
    }
}

/* --- the route (services/flight/src/guidance/route.rs) ------------------------------------------ */

static int waypoint_count(const struct guidance *g) {
    return g->list.count < MISSIONLINK_MAX_WAYPOINTS ? g->list.count : MISSIONLINK_MAX_WAYPOINTS;
}

static int index_of(const struct guidance *g, uint16_t number) {
    for (int i = 0; i < waypoint_count(g); i++) {
        if (g->list.waypoints[i].number == number) {
            return i;
        }
    }
    return -1;
}

static uint16_t number_of(const struct guidance *g, int index) {
    return index >= 0 && index < waypoint_count(g) ? g->list.waypoints[index].number : 0;
}

static bool on_ground(const struct guidance *g) {
    switch (g->automation.flight_phase) {
    case MISSIONLINK_FLIGHT_PHASE_TAKE_OFF:
    case MISSIONLINK_FLIGHT_PHASE_LANDING:
        return g->altitude_m <= 0.0;
    case MISSIONLINK_FLIGHT_PHASE_CRUISE:
        return false;
    default: /* on the ground, landed, or a phase byte not known */
        return true;
    }
}

static bool reversal_wanted(const struct guidance *g) {
    return g->automation.route_reversed && g->list.bidirectional;
}

/* The last waypoint of the route seen from TO at index to: land-at if still ahead. */
static int end_index(const struct guidance *g, int to) {
    uint16_t land_at = g->automation.land_at;
    if (land_at != 0) {
        int i = index_of(g, land_at);
        if (i >= 0 && ((!g->reversed && i >= to) || (g->reversed && i <= to))) {
            return i;
        }
    }
    return g->reversed ? 0 : waypoint_count(g) - 1;
}

/* The waypoint after the one at index to on the route, -1 on the last leg. */
static int next_index(const struct guidance *g, int to) {
    int end = end_index(g, to);
    if (g->reversed) {
        return to > end ? to - 1 : -1;
    }
    return to < end ? to + 1 : -1;
}

static void reset_route(struct guidance *g) {
    g->started = false;
    g->reversed = false;
    g->complete = false;
    g->from = 0;
    g->to = -1;
}

static void adopt(struct guidance *g, const WaypointListPayload *list) {
    if (list != &g->list) {
        g->list = *list;
    }
    g->has_pending = false;
    reset_route(g);
}

static void adopt_pending_if_due(struct guidance *g) {
    if (g->has_pending &&
        (on_ground(g) || g->automation.flown_waypoint_list == g->pending.generation)) {
        adopt(g, &g->pending);
    }
}

static void set_waypoint_list(struct guidance *g, const WaypointListPayload *list) {
    if (list->generation == g->list.generation) {
        return;
    }
    if (on_ground(g) || g->automation.flown_waypoint_list == list->generation) {
        adopt(g, list);
    } else {
        g->pending = *list;
        g->has_pending = true;
    }
}

static void set_automation(struct guidance *g, const AutomationStatePayload *state) {
    g->automation = *state;
    adopt_pending_if_due(g);
}

/* Starts the route: FROM 0, TO the first waypoint (reversed: the nearest one), flown direct. */
static void start_route_if_needed(struct guidance *g) {
    if (g->started) {
        return;
    }
    bool reversed = reversal_wanted(g);
    int to = -1;
    if (waypoint_count(g) > 0 && !reversed) {
        to = 0;
    } else if (waypoint_count(g) > 0) {
        double best = INFINITY;
        for (int i = 0; i < waypoint_count(g); i++) {
            const WaypointEntry *w = &g->list.waypoints[i];
            double d = distance_m(g->latitude_deg, g->longitude_deg, angle_deg(w->position.latitude),
                                  angle_deg(w->position.longitude));
            if (d < best) {
                best = d;
                to = i;
            }
        }
    }
    g->started = true;
    g->reversed = reversed;
    g->complete = false;
    g->from = 0;
    g->to = to;
}

/* A change of route_reversed: TO stays, what follows it turns round; a complete route starts
 * again from its final waypoint. */
static void sync_direction(struct guidance *g) {
    bool wanted = reversal_wanted(g);
    if (!g->started || wanted == g->reversed) {
        return;
    }
    g->reversed = wanted;
    if (g->complete) {
        int from = index_of(g, g->from);
        int next = from >= 0 ? next_index(g, from) : -1;
        if (next >= 0) {
            g->complete = false;
            g->to = next;
        }
    }
}

static void triple(const struct guidance *g, uint16_t *from, uint16_t *to, uint16_t *next) {
    uint8_t phase = g->automation.flight_phase;
    bool flying = phase == MISSIONLINK_FLIGHT_PHASE_TAKE_OFF ||
                  phase == MISSIONLINK_FLIGHT_PHASE_CRUISE ||
                  phase == MISSIONLINK_FLIGHT_PHASE_LANDING;
    if (flying && g->started) {
        *from = g->from;
        *to = number_of(g, g->to);
        *next = g->to >= 0 ? number_of(g, next_index(g, g->to)) : 0;
    } else {
        *from = *to = *next = 0;
    }
}

/* --- the kinematics ---------------------------------------------------------------------- */

static bool climb(struct guidance *g, double h) {
    double target = fmax(altitude_metres(g->list.take_off_height), 0.0);
    if (g->altitude_m >= target) {
        g->climb_complete = true;
        return false;
    }
    g->altitude_m = fmin(g->altitude_m + g->config.climb_rate_mps * h, target);
    if (g->altitude_m >= target - ALTITUDE_EPSILON_M) {
        g->altitude_m = target;
        g->climb_complete = true;
    }
    return true;
}

static bool descend(struct guidance *g, double h) {
    if (g->altitude_m <= 0.0) {
        g->altitude_m = 0.0;
        return false;
    }
    g->altitude_m = fmax(g->altitude_m - g->config.descent_rate_mps * h, 0.0);
    if (g->altitude_m <= ALTITUDE_EPSILON_M) {
        g->altitude_m = 0.0;
    }
    return true;
}

/* Flies towards TO for up to dt seconds; the time used (0 on arriving where it was), or -1
 * when there is nothing to fly. */
static double fly_leg(struct guidance *g, double dt) {
    if (g->to < 0) {
        return -1.0;
    }
    const WaypointEntry *w = &g->list.waypoints[g->to];
    double lat = angle_deg(w->position.latitude), lon = angle_deg(w->position.longitude);
    double target_alt = altitude_metres(w->altitude);
    double v = g->config.speed_mps;
    double d = distance_m(g->latitude_deg, g->longitude_deg, lat, lon);
    double budget = v * dt;
    g->ground_speed_mps = v;
    if (d > REACHED_M) {
        g->heading_deg = bearing_deg(g->latitude_deg, g->longitude_deg, lat, lon);
        g->heading_known = true;
    }
    if (d <= budget + REACHED_M) {
        g->latitude_deg = lat;
        g->longitude_deg = lon;
        g->altitude_m = target_alt;
        int next = next_index(g, g->to);
        g->from = w->number;
        g->to = next;
        g->complete = next < 0;
        return d / v;
    }
    g->altitude_m += (target_alt - g->altitude_m) * budget / d;
    destination(g->latitude_deg, g->longitude_deg, g->heading_deg, budget, &g->latitude_deg,
                &g->longitude_deg);
    return dt;
}

/* One cruise sub-step; false when holding (route complete or no list). */
static bool fly(struct guidance *g, double h) {
    double left = h;
    for (int i = 0; i < MAX_LEGS_PER_SUB_STEP && left > 0.0; i++) {
        double used = fly_leg(g, left);
        if (used < 0.0) {
            g->ground_speed_mps = 0.0;
            return false;
        }
        left -= used;
    }
    return true;
}

/* Integrates from the previous step to now_ns (time-scaled) and fills the progress. */
static void step(struct guidance *g, uint64_t now_ns, GuidanceProgressPayload *p) {
    g->sequence++;
    double elapsed = g->stepped ? (double)(now_ns - g->last_step_ns) / 1e9 : 0.0;
    g->last_step_ns = now_ns;
    g->stepped = true;
    adopt_pending_if_due(g);

    uint8_t phase = g->automation.flight_phase;
    if (phase == MISSIONLINK_FLIGHT_PHASE_TAKE_OFF || phase == MISSIONLINK_FLIGHT_PHASE_CRUISE) {
        start_route_if_needed(g);
    } else if (phase != MISSIONLINK_FLIGHT_PHASE_LANDING) {
        g->altitude_m = 0.0;
        g->climb_rate_mps = 0.0;
        reset_route(g);
        g->climb_complete = false;
    }
    sync_direction(g);
    if (phase != MISSIONLINK_FLIGHT_PHASE_CRUISE) {
        g->ground_speed_mps = 0.0;
    }

    double simulated = elapsed * g->config.time_scale;
    if (simulated > 0.0) {
        double n = fmax(ceil(simulated / MAX_SUB_STEP_S), 1.0);
        double h = simulated / n;
        for (double i = 0.0; i < n; i += 1.0) {
            double before = g->altitude_m;
            bool busy = false;
            if (phase == MISSIONLINK_FLIGHT_PHASE_TAKE_OFF) {
                busy = climb(g, h);
            } else if (phase == MISSIONLINK_FLIGHT_PHASE_CRUISE) {
                busy = fly(g, h);
            } else if (phase == MISSIONLINK_FLIGHT_PHASE_LANDING) {
                busy = descend(g, h);
            }
            /* Simulated seconds, so the time scale does not scale it. */
            g->climb_rate_mps = busy ? (g->altitude_m - before) / h : 0.0;
            if (!busy) {
                break;
            }
        }
    }

    memset(p, 0, sizeof *p);
    p->sequence = g->sequence;
    p->time_ns = now_ns;
    p->waypoint_list = g->list.generation;
    p->latitude_deg = g->latitude_deg;
    p->longitude_deg = g->longitude_deg;
    p->altitude_m = g->altitude_m;
    p->ground_speed_mps = g->ground_speed_mps;
    triple(g, &p->from, &p->to, &p->next);
    zone_status(g, &p->inside_fly_zone, &p->in_no_fly_zone);
    p->trajectory_generation_active = phase == MISSIONLINK_FLIGHT_PHASE_CRUISE;
    p->climb_complete = g->climb_complete;
    p->route_complete = g->complete;
    p->on_ground = on_ground(g);
    p->heading_deg = g->heading_known ? (float)g->heading_deg : NAN;
    if (p->heading_deg >= 360.0f) {
        p->heading_deg = 0.0f;
    }
    if (p->on_ground) {
        p->roll_deg = p->pitch_deg = p->climb_rate_mps = 0.0f;
    } else {
        /* Straight legs only: no bank. The pitch is the flight-path angle through the air. */
        p->roll_deg = 0.0f;
        p->pitch_deg = (float)degrees(atan2(g->climb_rate_mps, g->ground_speed_mps));
        p->climb_rate_mps = (float)g->climb_rate_mps;
    }
}

/* --- the lists, paired --------------------------------------------------------------------- */

static uint64_t newest(bool has_held, uint64_t held, const struct pairing *pairing) {
    uint64_t n = has_held ? held : 0;
    if (pairing->has_released && pairing->released > n) {
        n = pairing->released;
    }
    return n;
}

static void offer_waypoints(struct pairing *pairing, const WaypointListPayload *w) {
    if (w->activation < newest(pairing->has_waypoints, pairing->waypoints.activation, pairing)) {
        return; /* older than what is held or released: a dead predecessor's port */
    }
    pairing->waypoints = *w;
    pairing->has_waypoints = true;
}

static void offer_areas(struct pairing *pairing, const AreaListPayload *a) {
    if (a->activation < newest(pairing->has_areas, pairing->areas.activation, pairing)) {
        return;
    }
    pairing->areas = *a;
    pairing->has_areas = true;
}

static bool take_pair(struct pairing *pairing) {
    if (!pairing->has_waypoints || !pairing->has_areas ||
        pairing->waypoints.activation != pairing->areas.activation) {
        return false;
    }
    if (pairing->has_released && pairing->waypoints.activation <= pairing->released) {
        return false;
    }
    pairing->released = pairing->waypoints.activation;
    pairing->has_released = true;
    return true;
}

/* --- the partition ------------------------------------------------------------------------- */

static bool check(int32_t status, const char *what) {
    if (status >= 0) {
        return true;
    }
    char message[512];
    missionlink_last_error(message, sizeof message);
    log_line("%s failed: %s: %s", what, missionlink_status_name(status), message);
    return false;
}

/* The partition's state: static, the payloads are several kilobytes each. */
static struct guidance g;
static struct pairing pairing;
static WaypointListPayload waypoints_in;
static AreaListPayload areas_in;

static int run(const struct config *config) {
    missionlink_partition *partition = NULL;
    if (!check(missionlink_partition_open("guidance-c", config->service_prefix,
                                          MISSIONLINK_ROLE_GUIDANCE,
                                          (uint64_t)config->heartbeat_period_ms * 1000000ull,
                                          &partition),
               "opening the partition")) {
        return 1;
    }
    bool ok = check(missionlink_subscriber_open(partition,
                                                MISSIONLINK_SERVICE_ID_MISSION_WAYPOINT_LIST),
                    "subscribing to the waypoint list") &&
              check(missionlink_subscriber_open(partition,
                                                MISSIONLINK_SERVICE_ID_MISSION_AREA_LIST),
                    "subscribing to the area list") &&
              check(missionlink_subscriber_open(partition, MISSIONLINK_SERVICE_ID_AUTOMATION_STATE),
                    "subscribing to the automation state") &&
              check(missionlink_publisher_open(partition, MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS),
                    "publishing progress");
    if (!ok) {
        missionlink_partition_close(partition);
        return 1;
    }

    memset(&g, 0, sizeof g);
    g.config = *config;
    g.latitude_deg = config->start_latitude_deg;
    g.longitude_deg = config->start_longitude_deg;
    g.automation.flight_phase = MISSIONLINK_FLIGHT_PHASE_ON_GROUND;
    reset_route(&g);

    log_line("guidance up prefix=%s time_scale=%g speed_mps=%g heartbeat_period_ms=%ld pid=%ld",
             config->service_prefix, config->time_scale, config->speed_mps,
             config->heartbeat_period_ms, (long)getpid());

    GuidanceProgressPayload progress, last_published;
    memset(&progress, 0, sizeof progress);
    memset(&last_published, 0, sizeof last_published);
    bool published = false;
    uint64_t last_sent_ns = 0, last_position_log_ns = 0, loops = 0;
    uint64_t interval_ns = (uint64_t)config->update_interval_ms * 1000000ull;
    int status = 0;
    while (!stop_requested) {
        uint64_t next_beat_ns = interval_ns;
        if (!check(missionlink_heartbeat(partition, &next_beat_ns), "heartbeat")) {
            status = 1;
            break;
        }
        loops++;

        int32_t r;
        while ((r = missionlink_take(partition, MISSIONLINK_SERVICE_ID_MISSION_WAYPOINT_LIST,
                                     &waypoints_in, sizeof waypoints_in)) == MISSIONLINK_OK) {
            offer_waypoints(&pairing, &waypoints_in);
        }
        ok = check(r, "taking the waypoint list");
        while ((r = missionlink_take(partition, MISSIONLINK_SERVICE_ID_MISSION_AREA_LIST,
                                     &areas_in, sizeof areas_in)) == MISSIONLINK_OK) {
            offer_areas(&pairing, &areas_in);
        }
        ok = check(r, "taking the area list") && ok;
        /* Only whole pairs of one activation, both set before the step. */
        if (take_pair(&pairing)) {
            log_line("waypoint list received generation=%llu waypoints=%u activation=%llu",
                     (unsigned long long)pairing.waypoints.generation,
                     (unsigned)pairing.waypoints.count,
                     (unsigned long long)pairing.waypoints.activation);
            log_line("area list received generation=%llu activation=%llu",
                     (unsigned long long)pairing.areas.generation,
                     (unsigned long long)pairing.areas.activation);
            set_waypoint_list(&g, &pairing.waypoints);
            g.areas = pairing.areas;
        }
        AutomationStatePayload state;
        r = missionlink_take_latest(partition, MISSIONLINK_SERVICE_ID_AUTOMATION_STATE, &state,
                                    sizeof state);
        if (r == MISSIONLINK_OK) {
            set_automation(&g, &state);
        }
        ok = check(r, "taking the automation state") && ok;
        if (!ok) {
            status = 1;
            break;
        }

        uint64_t now = monotonic_ns();
        step(&g, now, &progress);
        if (!published || progress.from != last_published.from ||
            progress.to != last_published.to || progress.next != last_published.next) {
            log_line("from-to-next from=%u to=%u next=%u", (unsigned)progress.from,
                     (unsigned)progress.to, (unsigned)progress.next);
        }
        /* A change is any byte but the counters' (NaN compares by its bytes too). */
        GuidanceProgressPayload a = progress, b = last_published;
        a.sequence = b.sequence = 0;
        a.time_ns = b.time_ns = 0;
        if (!published || memcmp(&a, &b, sizeof a) != 0 || now - last_sent_ns >= REPUBLISH_NS) {
            if (!check(missionlink_publish(partition, MISSIONLINK_SERVICE_ID_GUIDANCE_PROGRESS,
                                           &progress, sizeof progress),
                       "publishing progress")) {
                status = 1;
                break;
            }
            last_published = progress;
            published = true;
            last_sent_ns = now;
        }
        if (now - last_position_log_ns >= POSITION_LOG_NS) {
            last_position_log_ns = now;
            log_line("position latitude=%.7f longitude=%.7f altitude=%.2f from=%u to=%u next=%u",
                     progress.latitude_deg, progress.longitude_deg, progress.altitude_m,
                     (unsigned)progress.from, (unsigned)progress.to, (unsigned)progress.next);
        }

        uint64_t timeout = next_beat_ns < interval_ns ? next_beat_ns : interval_ns;
        if (!check(missionlink_wait(partition, timeout), "waiting")) {
            status = 1;
            break;
        }
    }
    log_line("guidance stopping steps=%llu loops=%llu", (unsigned long long)g.sequence,
             (unsigned long long)loops);
    missionlink_partition_close(partition);
    return status;
}

static void usage(const char *program) {
    fprintf(stderr,
            "usage: %s [--service-prefix P] [--time-scale X] [--start-latitude DEG]\n"
            "          [--start-longitude DEG] [--climb-rate MPS] [--descent-rate MPS]\n"
            "          [--speed-mps MPS] [--update-interval-ms MS] [--heartbeat-period-ms MS]\n"
            "Guidance partition of the FCC in C (replaces guidance-stub: fcc --without "
            "guidance-stub).\n",
            program);
}

static bool parse_double(const char *text, double *out) {
    char *end = NULL;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || !isfinite(v)) {
        return false;
    }
    *out = v;
    return true;
}

static bool parse_long(const char *text, long *out) {
    char *end = NULL;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || v <= 0) {
        return false;
    }
    *out = v;
    return true;
}

int main(int argc, char **argv) {
    struct config config = {
        .service_prefix = MISSIONLINK_DEFAULT_SERVICE_PREFIX,
        .time_scale = 1.0,
        .start_latitude_deg = 48.26, /* TROL, as the Rust stub's default */
        .start_longitude_deg = 11.66,
        .climb_rate_mps = 3.0,
        .descent_rate_mps = 2.0,
        .speed_mps = 25.0,
        .update_interval_ms = 50,
        .heartbeat_period_ms = MISSIONLINK_DEFAULT_HEARTBEAT_PERIOD_MS,
    };
    for (int i = 1; i < argc; i++) {
        const char *flag = argv[i];
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok = value != NULL;
        if (ok && strcmp(flag, "--service-prefix") == 0) {
            config.service_prefix = value;
        } else if (ok && strcmp(flag, "--time-scale") == 0) {
            ok = parse_double(value, &config.time_scale) && config.time_scale > 0.0;
        } else if (ok && strcmp(flag, "--start-latitude") == 0) {
            ok = parse_double(value, &config.start_latitude_deg) &&
                 fabs(config.start_latitude_deg) <= 90.0;
        } else if (ok && strcmp(flag, "--start-longitude") == 0) {
            ok = parse_double(value, &config.start_longitude_deg) &&
                 fabs(config.start_longitude_deg) <= 180.0;
        } else if (ok && strcmp(flag, "--climb-rate") == 0) {
            ok = parse_double(value, &config.climb_rate_mps) && config.climb_rate_mps > 0.0;
        } else if (ok && strcmp(flag, "--descent-rate") == 0) {
            ok = parse_double(value, &config.descent_rate_mps) && config.descent_rate_mps > 0.0;
        } else if (ok && strcmp(flag, "--speed-mps") == 0) {
            ok = parse_double(value, &config.speed_mps) && config.speed_mps > 0.0;
        } else if (ok && strcmp(flag, "--update-interval-ms") == 0) {
            ok = parse_long(value, &config.update_interval_ms);
        } else if (ok && strcmp(flag, "--heartbeat-period-ms") == 0) {
            ok = parse_long(value, &config.heartbeat_period_ms);
        } else {
            ok = false;
        }
        if (!ok) {
            fprintf(stderr, "%s: bad argument %s %s\n", argv[0], flag, value ? value : "");
            usage(argv[0]);
            return 2;
        }
        i++;
    }

    /* No SA_RESTART: the signal ends a wait on the doorbell, and the loop sees the flag. */
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGTERM, &action, NULL);
    sigaction(SIGINT, &action, NULL);

    return run(&config);
}
