-- Wireshark dissector for missionlink's STANAG 4586 mission and area transfer ICD (edition 2).
--
-- Decodes every message of ICD §4 (edition-2 fields included), the signature trailer of ICD §9
-- and datagrams that hold several messages back to back (ICD §1), with every field in the units
-- and names `gcs inspect --json` prints: angles in degrees, altitudes and distances in metres,
-- speeds in m/s, time stamps as RFC 3339 UTC, enumerated values by the same snake_case names.
-- Frames that break a rule of ICD §2 (short frame, Message Length 0 or above 528 or not what
-- the datagram holds, checksum length code 11, wrong checksum, IDD version outside 30..=40)
-- carry expert info, and so do messages that break §3 (unknown presence bit, truncated field).
--
-- This file is the one copy of the message layouts outside the Rust wire layer; the test
-- `gcs/tests/dissector.rs` keeps the two together: it checks every field label against
-- `MessageType::fields()`, every value name against the Rust enumerations, and every field of
-- captures of every message type against `gcs inspect --json`.
--
-- Load it: `wireshark -X lua_script:tools/wireshark/missionlink.lua` (or copy it into the
-- personal plugins folder, Help > About > Folders). Ports: Edit > Preferences > Protocols >
-- MISSIONLINK, default the four ports of ICD §1; other ports are found by a heuristic.

local p = Proto("missionlink", "STANAG 4586 missionlink ICD")

p.prefs.ports = Pref.range("UDP ports", "4586-4589",
    "UDP ports of the direct and the LTE link, both sides (ICD §1 defaults: 4586-4589)", 65535)
p.prefs.heuristic = Pref.bool("Find the ICD on other ports", true,
    "Try every UDP datagram on other ports: wrapper reserved 0xFFFF, a known message type, " ..
    "IDD version 30..40 and a length that fits (the demo and the tests use ports the system chooses)")

-- ICD §2: wrapper sizes and rules.
local HEADER_LEN = 16
local MAX_DATA_LEN = 528
local TRAILER_LEN = 16
local IDD_MIN, IDD_MAX = 30, 40

-- Enumerated values (ICD §4, §6), named as `gcs inspect --json` names them.
local V = {
    ack_type = { [0] = "received", "partially_received", "completed", "rejected", "receive_failed" },
    mission_plan_mode = { [1] = "clear_mission", [2] = "transmit_mission", [3] = "receive_mission",
        [5] = "cancel_transfer", [6] = "delete_staged_mission", [7] = "report_missions",
        [8] = "stage_mission", [9] = "receive_staged_mission", [10] = "load_waypoint_buffer" },
    route_type = { [0] = "launch", "approach", "flight", "contingency_a", "contingency_b" },
    location_type = { [0] = "absolute" },
    altitude_type = { [0] = "pressure", "baro", "agl", "wgs84" },
    speed_type = { [0] = "indicated_airspeed", "true_airspeed", "ground_speed" },
    turn_type = { [0] = "fly_by", "fly_over" },
    leg_type = { [0] = "track_to_fix", "radius_to_fix" },
    turn_direction = { [0] = "clockwise", "counter_clockwise" },
    transfer_status = { [0] = "in_progress", "complete", "aborted" },
    area_transfer_mode = { [1] = "initiate_upload", [2] = "upload_complete", [3] = "initiate_download",
        [4] = "download_complete", [5] = "cancel", [6] = "clear_areas", [7] = "upload_complete_staged",
        [8] = "initiate_staged_download" },
    area_type = { [0] = "fly_zone", "no_fly_zone" },
    area_list_status = { [0] = "invalid", "valid" },
    area_download_status = { [0] = "ready", [2] = "aborted" },
    execute_command = { [1] = "execute", [2] = "return_to_home", [3] = "land", [4] = "activate_staged" },
    geofence_check = { [0] = "not_run", "passed", "failed" },
    reason = { [0] = "none", "malformed", "missing_field", "unknown_field", "unsupported",
        "capacity", "wrong_state", "guidance_active", "count_mismatch", "broken_chain",
        "missing_initial", "missing_rf_centre", "bad_geometry", "busy", "geofence_violation",
        "integrity_mismatch" },
    specific_data_type = { [1] = "take_off_height", [2] = "rf_centre" },
    area_shape = { [0] = "polygon", "circle" },
    checksum_width = { [0] = "none", "two", "four", "invalid" },
    link_id = { [0] = "direct", "lte" },
}

-- Field kinds (ICD §3): size in bytes, the ProtoField it makes, how its value is read.
local function ts_text(range)
    local ms = range:uint64():tonumber()
    local secs = math.floor(ms / 1000)
    -- 946684800 s: 2000-01-01T00:00:00Z after the Unix epoch.
    return os.date("!%Y-%m-%dT%H:%M:%S", secs + 946684800) .. string.format(".%03dZ", ms - secs * 1000)
end

local function text(range)
    return range:stringz(ENC_UTF_8)
end

local K = {
    TS = { size = 5, make = ProtoField.string, value = ts_text },
    U1 = { size = 1, make = ProtoField.uint8 },
    U2 = { size = 2, make = ProtoField.uint16 },
    U3 = { size = 3, make = ProtoField.uint24 },
    U4 = { size = 4, make = ProtoField.uint32 },
    BAM4 = { size = 4, make = ProtoField.double, unit = " °",
        value = function(r) return r:int() * (180 / 2147483648) end },
    ALT3 = { size = 3, make = ProtoField.double, unit = " m",
        value = function(r) return r:int() / 50 end },
    SPD2 = { size = 2, make = ProtoField.double, unit = " m/s",
        value = function(r) return r:uint() * 0.5 end },
    VEL2 = { size = 2, make = ProtoField.double, unit = " m/s",
        value = function(r) return r:int() * 0.05 end },
    I2 = { size = 2, make = ProtoField.int16, value = function(r) return r:int() end },
    OFFSET2 = { size = 2, make = ProtoField.double, unit = " m",
        value = function(r) return r:uint() / 10 end },
    CHAR20 = { size = 20, make = ProtoField.string, value = text },
    CHAR33 = { size = 33, make = ProtoField.string, value = text },
}

-- An enumerated U1 field.
local function E(values) return { kind = "U1", values = values } end

-- The messages of ICD §4: per presence-vector bit (in order from bit 0), the ICD's field name,
-- the key `gcs inspect --json` gives it, and its kind. Special kinds: `window_or_checksum`
-- (#2011 bit 7, by mode), `vertices` (#2012 bit 8), `route_activity` (#13001 Activity ID: bit 0
-- is `bidirectional`).
local MESSAGES = {
    [17000] = { name = "Message Acknowledgement", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Original Message Time Stamp", "original_time_stamp", "TS" },
        { "Original Message Type", "original_message_type", "U2" },
        { "Acknowledgement Type", "ack_type", E(V.ack_type) },
        { "Reject Reason", "reject_reason", E(V.reason) },
    } },
    [13000] = { name = "Mission Transfer Command", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Mission ID", "mission_id", "CHAR20" },
        { "Mission Plan Mode", "mode", E(V.mission_plan_mode) },
        { "Waypoint Number", "waypoint_number", "U2" },
        { "Route ID", "route_id", "CHAR33" },
        { "Activity ID", "activity_id", "U3" },
        { "Transfer Window", "transfer_window", "U1" },
        { "Mission Checksum", "mission_checksum", "U4" },
    } },
    [13001] = { name = "UA Route", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Initial Waypoint Number", "initial_waypoint", "U2" },
        { "Route ID", "route_id", "CHAR33" },
        { "Route Type", "route_type", E(V.route_type) },
        { "Activity ID", "activity_id", "route_activity" },
        { "Planning Wind Speed", "planning_wind", "SPD2" },
    } },
    [13002] = { name = "UA Position Waypoint", pv = 3, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Waypoint Number", "waypoint_number", "U2" },
        { "Waypoint to Latitude", "latitude", "BAM4" },
        { "Waypoint to Longitude", "longitude", "BAM4" },
        { "Location Type", "location_type", E(V.location_type) },
        { "Waypoint to Altitude", "altitude", "ALT3" },
        { "Waypoint Altitude Type", "altitude_type", E(V.altitude_type) },
        { "Altitude Change Behaviour", "altitude_change_behaviour", "U1" },
        { "Waypoint to Speed", "speed", "SPD2" },
        { "Waypoint Speed Type", "speed_type", E(V.speed_type) },
        { "Next Waypoint", "next_waypoint", "U2" },
        { "Turn Type", "turn_type", E(V.turn_type) },
        { "Optional Messages for Waypoint", "optional_messages", "U1" },
        { "Waypoint Type", "leg_type", E(V.leg_type) },
        { "Limit Type", "limit_type", "U1" },
        { "Loop Limit", "loop_limit", "U2" },
        { "Arrival Time", "arrival_time", "TS" },
        { "Activity ID", "activity_id", "U3" },
    } },
    [13006] = { name = "Vehicle Specific Waypoint", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Waypoint Number", "waypoint_number", "U2" },
        { "Specific Data Type", "specific_data_type", E(V.specific_data_type) },
        { "Take-off Height", "take_off_height", "ALT3" },
        { "RF Centre Latitude", "rf_centre_latitude", "BAM4" },
        { "RF Centre Longitude", "rf_centre_longitude", "BAM4" },
        { "Turn Direction", "turn_direction", E(V.turn_direction) },
        { "Activity ID", "activity_id", "U3" },
    } },
    [14000] = { name = "Mission Upload/Download Status", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Mission ID", "mission_id", "CHAR20" },
        { "Status", "status", E(V.transfer_status) },
        { "Percent Complete", "percent_complete", "U1" },
        { "Waypoint Request", "waypoint_request", "U2" },
        { "Mission Plan Mode", "mode", E(V.mission_plan_mode) },
        { "Reason", "reason", E(V.reason) },
        { "Mission Checksum", "mission_checksum", "U4" },
    } },
    [4001] = { name = "FROM-TO-NEXT Waypoint States", pv = 3, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Altitude Type", "altitude_type", E(V.altitude_type) },
        { "Speed Type", "speed_type", E(V.speed_type) },
        { "From Latitude", "from.latitude", "BAM4" },
        { "From Longitude", "from.longitude", "BAM4" },
        { "From Altitude", "from.altitude", "ALT3" },
        { "From Time", "from.time", "TS" },
        { "From Waypoint Number", "from.waypoint_number", "U2" },
        { "To Latitude", "to.latitude", "BAM4" },
        { "To Longitude", "to.longitude", "BAM4" },
        { "To Altitude", "to.altitude", "ALT3" },
        { "To Speed", "to.speed", "SPD2" },
        { "To Time", "to.time", "TS" },
        { "To Waypoint Number", "to.waypoint_number", "U2" },
        { "Next Latitude", "next.latitude", "BAM4" },
        { "Next Longitude", "next.longitude", "BAM4" },
        { "Next Altitude", "next.altitude", "ALT3" },
        { "Next Speed", "next.speed", "SPD2" },
        { "Next Time", "next.time", "TS" },
        { "Next Waypoint Number", "next.waypoint_number", "U2" },
        { "Loiter Configuration Report Validity", "loiter_configuration_report_validity", "U1" },
    } },
    [101] = { name = "Inertial States", pv = 3, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Latitude", "latitude", "BAM4" },
        { "Longitude", "longitude", "BAM4" },
        { "Altitude", "altitude", "ALT3" },
        { "Altitude Type", "altitude_type", E(V.altitude_type) },
        { "U Speed", "u_speed", "VEL2" },
        { "V Speed", "v_speed", "VEL2" },
        { "W Speed", "w_speed", "VEL2" },
        { "U Accel", "u_accel", "I2" },
        { "V Accel", "v_accel", "I2" },
        { "W Accel", "w_accel", "I2" },
        { "Phi", "phi", "I2" },
        { "Theta", "theta", "I2" },
        { "Psi", "psi", "I2" },
        { "Phi Dot", "phi_dot", "I2" },
        { "Theta Dot", "theta_dot", "I2" },
        { "Psi Dot", "psi_dot", "I2" },
        { "Magnetic Variation", "magnetic_variation", "I2" },
    } },
    [2011] = { name = "Area Transmission Command", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Area Transfer Mode", "mode", E(V.area_transfer_mode) },
        { "Area Loop Count", "loop_count", "U1" },
        { "Area ID", "area_id", "U2" },
        { "Safety Offset", "safety_offset", "OFFSET2" },
        { "Activity ID", "activity_id", "U3" },
        { "Mission ID", "mission_id", "CHAR20" },
        { "Transfer Window or Area Checksum", "window_or_checksum", "window_or_checksum" },
    } },
    [2012] = { name = "Area Polygon Loop Segment", pv = 2, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Area ID", "area_id", "U2" },
        { "Area Type", "area_type", E(V.area_type) },
        -- The shape rides in Activity ID (U3: 0 polygon, 1 circle).
        { "Activity ID", "shape", { kind = "U3", values = V.area_shape } },
        { "Lower Altitude", "lower_altitude", "ALT3" },
        { "Upper Altitude", "upper_altitude", "ALT3" },
        { "Altitude Type", "altitude_type", E(V.altitude_type) },
        { "Vertex Count", "vertex_count", "U1" },
        { "Vertices", "vertices", "vertices" },
    } },
    [3012] = { name = "Area Status Alert", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Area Loop Count", "loop_count", "U1" },
        { "Status", "status", E(V.area_list_status) },
        { "Reason", "reason", E(V.reason) },
    } },
    [3013] = { name = "Area Transmission Status", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Area ID", "area_id", "U2" },
        { "Area Loop Count", "loop_count", "U1" },
        { "Safety Offset", "safety_offset", "OFFSET2" },
        { "Status", "status", E(V.area_download_status) },
    } },
    [50000] = { name = "Mission Execute Command", pv = 1, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Command", "command", E(V.execute_command) },
        { "Mission ID", "mission_id", "CHAR20" },
    } },
    [50001] = { name = "Mission Report", pv = 2, fields = {
        { "Time Stamp", "time_stamp", "TS" },
        { "Report Index", "report_index", "U1" },
        { "Report Count", "report_count", "U1" },
        { "Mission ID", "mission_id", "CHAR20" },
        { "Waypoint Count", "waypoint_count", "U2" },
        { "Area Count", "area_count", "U1" },
        { "Geofence Check", "geofence_check", E(V.geofence_check) },
        { "Reason", "reason", E(V.reason) },
        { "Mission Checksum", "mission_checksum", "U4" },
        { "Area Checksum", "area_checksum", "U4" },
    } },
}

-- Wrapper (ICD §2) and trailer (ICD §9) fields.
local message_names = {}
for t, m in pairs(MESSAGES) do message_names[t] = m.name end

local f = {
    reserved = ProtoField.uint16("missionlink.reserved", "Reserved (sequence)", base.HEX),
    length = ProtoField.uint16("missionlink.length", "Message Length", base.DEC),
    source_id = ProtoField.uint32("missionlink.source_id", "Source ID", base.HEX),
    destination_id = ProtoField.uint32("missionlink.destination_id", "Destination ID", base.HEX),
    message_type = ProtoField.uint16("missionlink.message_type", "Message Type", base.DEC,
        message_names),
    properties = ProtoField.uint16("missionlink.properties", "Message Properties", base.HEX),
    ack_requested = ProtoField.bool("missionlink.ack_requested", "Acknowledgement requested", 16,
        nil, 0x8000),
    idd_version = ProtoField.uint16("missionlink.idd_version", "IDD version", base.DEC, nil, 0x7f00),
    checksum_width = ProtoField.uint16("missionlink.checksum_width", "Checksum length", base.DEC,
        V.checksum_width, 0x00c0),
    signed = ProtoField.bool("missionlink.signed", "Signed (ICD §9)", 16, nil, 0x0020),
    properties_reserved = ProtoField.uint16("missionlink.properties_reserved", "Reserved bits",
        base.HEX, nil, 0x001f),
    frame_length = ProtoField.uint32("missionlink.frame_length", "Frame length (header, data, checksum)",
        base.DEC),
    presence_vector = ProtoField.uint24("missionlink.presence_vector", "Presence Vector", base.HEX),
    checksum = ProtoField.uint32("missionlink.checksum", "Checksum", base.HEX),
    checksum_computed = ProtoField.uint32("missionlink.checksum_computed", "Checksum computed",
        base.HEX),
    key_id = ProtoField.uint8("missionlink.signature.key_id", "Key ID", base.DEC),
    link_id = ProtoField.uint8("missionlink.signature.link_id", "Link ID", base.DEC, V.link_id),
    trailer_reserved = ProtoField.uint16("missionlink.signature.reserved", "Reserved", base.DEC),
    signature = ProtoField.bytes("missionlink.signature.signature", "Signature (HMAC-SHA-256, 12 bytes)"),
    unparsed = ProtoField.bytes("missionlink.unparsed", "Bytes after the last field"),
}

-- Message fields: one ProtoField per (message, key), named as the ICD names the field; the
-- description says which presence bit it is, which the test checks against the Rust wire layer.
local mf = {}
for t, m in pairs(MESSAGES) do
    mf[t] = {}
    for i, def in ipairs(m.fields) do
        local label, key, kind = def[1], def[2], def[3]
        local abbrev = string.format("missionlink.m%d.%s", t, key)
        local blurb = string.format("#%d bit %d", t, i - 1)
        if type(kind) == "table" then
            local make = K[kind.kind].make
            mf[t][key] = make(abbrev, label, base.DEC, kind.values, nil, blurb)
        elseif kind == "window_or_checksum" then
            mf[t].transfer_window = ProtoField.uint32(
                string.format("missionlink.m%d.transfer_window", t), label, base.DEC, nil, nil, blurb)
            mf[t].area_checksum = ProtoField.uint32(
                string.format("missionlink.m%d.area_checksum", t), label, base.DEC, nil, nil, blurb)
        elseif kind == "vertices" then
            mf[t].vertices = ProtoField.none(abbrev, label, blurb)
            mf[t]["vertices.latitude"] = ProtoField.double(abbrev .. ".latitude", "Latitude")
            mf[t]["vertices.longitude"] = ProtoField.double(abbrev .. ".longitude", "Longitude")
        elseif kind == "route_activity" then
            mf[t].activity_id = ProtoField.uint24(abbrev, label, base.DEC, nil, nil, blurb)
            mf[t].bidirectional = ProtoField.bool(string.format("missionlink.m%d.bidirectional", t),
                "Bidirectional route", 24, nil, 0x000001)
        elseif K[kind].make == ProtoField.string then
            -- Wireshark 4.2 added the display argument before the description.
            if base.UNICODE then
                mf[t][key] = ProtoField.string(abbrev, label, base.UNICODE, blurb)
            else
                mf[t][key] = ProtoField.string(abbrev, label, blurb)
            end
        elseif K[kind].make == ProtoField.double then
            mf[t][key] = ProtoField.double(abbrev, label, blurb)
        else
            mf[t][key] = K[kind].make(abbrev, label, base.DEC, nil, nil, blurb)
        end
    end
end

local all = {}
for _, v in pairs(f) do table.insert(all, v) end
for _, fields in pairs(mf) do
    for _, v in pairs(fields) do table.insert(all, v) end
end
p.fields = all

-- Expert info: the rejection rules of ICD §2 and the message rules of ICD §3.
local ex = {
    too_short = ProtoExpert.new("missionlink.too_short", "Frame shorter than the 16-byte header (ICD §2)",
        expert.group.MALFORMED, expert.severity.ERROR),
    bad_length = ProtoExpert.new("missionlink.bad_length",
        "Message Length is 0 or above 528 (ICD §2)", expert.group.MALFORMED, expert.severity.ERROR),
    length_mismatch = ProtoExpert.new("missionlink.length_mismatch",
        "Message Length disagrees with the datagram (ICD §2)", expert.group.MALFORMED,
        expert.severity.ERROR),
    bad_checksum_code = ProtoExpert.new("missionlink.bad_checksum_code",
        "Checksum length code 11 is invalid (ICD §2)", expert.group.MALFORMED, expert.severity.ERROR),
    bad_checksum = ProtoExpert.new("missionlink.bad_checksum", "Checksum wrong (ICD §2)",
        expert.group.CHECKSUM, expert.severity.ERROR),
    bad_version = ProtoExpert.new("missionlink.bad_version",
        "IDD version outside 30..=40: rejected at the wrapper", expert.group.PROTOCOL,
        expert.severity.ERROR),
    no_trailer = ProtoExpert.new("missionlink.no_trailer",
        "Signed frame without its 16-byte trailer (ICD §9)", expert.group.MALFORMED,
        expert.severity.WARN),
    unknown_type = ProtoExpert.new("missionlink.unknown_type", "Message type not in the ICD",
        expert.group.UNDECODED, expert.severity.WARN),
    unknown_field = ProtoExpert.new("missionlink.unknown_field",
        "Presence vector bit beyond the defined fields (ICD §3: UnknownField)",
        expert.group.MALFORMED, expert.severity.ERROR),
    truncated = ProtoExpert.new("missionlink.truncated",
        "Message data ends inside a field (Malformed)", expert.group.MALFORMED, expert.severity.ERROR),
    trailing = ProtoExpert.new("missionlink.trailing",
        "Bytes after the last present field (Malformed)", expert.group.MALFORMED, expert.severity.ERROR),
}
p.experts = ex

-- The message data: presence vector, then the present fields in order (ICD §3).
local function dissect_data(tvb, tree, t, off, len)
    local m = MESSAGES[t]
    local stop = off + len
    if len < m.pv then
        tree:add_proto_expert_info(ex.truncated)
        return
    end
    local pv = tvb(off, m.pv):uint()
    tree:add(f.presence_vector, tvb(off, m.pv))
    local pos = off + m.pv
    local decoded = {}
    for bit = 0, m.pv * 8 - 1 do
        if bit32.band(pv, bit32.lshift(1, bit)) ~= 0 then
            local def = m.fields[bit + 1]
            if def == nil then
                tree:add_proto_expert_info(ex.unknown_field,
                    string.format("Presence vector bit %d: #%d defines bits 0..%d (ICD §3: UnknownField)",
                        bit, t, #m.fields - 1))
                return
            end
            local label, key, kind = def[1], def[2], def[3]
            local size
            if type(kind) == "table" then
                size = K[kind.kind].size
            elseif kind == "window_or_checksum" then
                size = 4
            elseif kind == "vertices" then
                size = 8 * (decoded.vertex_count or 0)
            elseif kind == "route_activity" then
                size = 3
            else
                size = K[kind].size
            end
            if pos + size > stop then
                tree:add_proto_expert_info(ex.truncated,
                    string.format("%s (bit %d) needs %d bytes, %d left (Malformed)", label, bit, size,
                        stop - pos))
                return
            end
            local r = tvb(pos, size)
            if type(kind) == "table" then
                decoded[key] = r:uint()
                tree:add(mf[t][key], r)
            elseif kind == "window_or_checksum" then
                -- ICD §4 #2011 bit 7: the Transfer Window with modes 3 and 8, else the checksum.
                if decoded.mode == 3 or decoded.mode == 8 then
                    tree:add(mf[t].transfer_window, r)
                else
                    tree:add(mf[t].area_checksum, r)
                end
            elseif kind == "vertices" then
                local vt = tree:add(mf[t].vertices, r)
                for i = 0, (decoded.vertex_count or 0) - 1 do
                    local at = tvb(pos + 8 * i, 8)
                    local vx = vt:add(at, string.format("Vertex %d", i + 1))
                    local lat = K.BAM4.value(tvb(pos + 8 * i, 4))
                    local lon = K.BAM4.value(tvb(pos + 8 * i + 4, 4))
                    vx:add(mf[t]["vertices.latitude"], tvb(pos + 8 * i, 4), lat):append_text(" °")
                    vx:add(mf[t]["vertices.longitude"], tvb(pos + 8 * i + 4, 4), lon):append_text(" °")
                    vx:append_text(string.format(": %.7f, %.7f", lat, lon))
                end
            elseif kind == "route_activity" then
                local at = tree:add(mf[t].activity_id, r)
                at:add(mf[t].bidirectional, r)
            else
                local k = K[kind]
                if k.value then
                    local item = tree:add(mf[t][key], r, k.value(r))
                    if k.unit then item:append_text(k.unit) end
                else
                    decoded[key] = r:uint()
                    tree:add(mf[t][key], r)
                end
            end
            pos = pos + size
        end
    end
    if pos < stop then
        tree:add(f.unparsed, tvb(pos, stop - pos))
        tree:add_proto_expert_info(ex.trailing)
    end
end

-- One frame at `off`; returns where the next one starts, or nil when the walk must stop (as
-- the Rust walker `wire::frames` stops: nothing after a broken frame can be located).
local function dissect_frame(tvb, pinfo, root, off, index)
    local rest = tvb:len() - off
    local tree = root:add(p, tvb(off, rest), string.format("STANAG 4586 message %d", index))
    if rest < HEADER_LEN then
        tree:add_proto_expert_info(ex.too_short,
            string.format("%d bytes, shorter than the 16-byte header (ICD §2)", rest))
        return nil
    end
    local length = tvb(off + 2, 2):uint()
    local t = tvb(off + 12, 2):uint()
    local props = tvb(off + 14, 2):uint()
    tree:add(f.reserved, tvb(off, 2))
    local length_item = tree:add(f.length, tvb(off + 2, 2))
    tree:add(f.source_id, tvb(off + 4, 4))
    tree:add(f.destination_id, tvb(off + 8, 4))
    local type_item = tree:add(f.message_type, tvb(off + 12, 2))
    local pt = tree:add(f.properties, tvb(off + 14, 2))
    pt:add(f.ack_requested, tvb(off + 14, 2))
    pt:add(f.idd_version, tvb(off + 14, 2))
    local code_item = pt:add(f.checksum_width, tvb(off + 14, 2))
    pt:add(f.signed, tvb(off + 14, 2))
    pt:add(f.properties_reserved, tvb(off + 14, 2))
    local name = MESSAGES[t] and MESSAGES[t].name or "unknown message type"
    tree:set_text(string.format("STANAG 4586 #%d %s", t, name))
    if MESSAGES[t] == nil then
        type_item:add_proto_expert_info(ex.unknown_type)
    end

    if length == 0 or length > MAX_DATA_LEN then
        length_item:add_proto_expert_info(ex.bad_length,
            string.format("Message Length %d: must be 1..=528 (ICD §2)", length))
        return nil
    end
    local code = bit32.rshift(bit32.band(props, 0x00c0), 6)
    if code == 3 then
        code_item:add_proto_expert_info(ex.bad_checksum_code)
        return nil
    end
    local width = ({ [0] = 0, 2, 4 })[code]
    local total = HEADER_LEN + length + width
    if total > rest then
        length_item:add_proto_expert_info(ex.length_mismatch,
            string.format("The wrapper says the message takes %d bytes, the datagram has %d (ICD §2)",
                total, rest))
        return nil
    end
    tree:set_len(total)
    tree:add(f.frame_length, tvb(off, total), total):set_generated()

    if MESSAGES[t] then
        dissect_data(tvb, tree, t, off + HEADER_LEN, length)
    end

    local ok = true
    if width > 0 then
        local sum = 0
        for i = off, off + HEADER_LEN + length - 1 do
            sum = sum + tvb(i, 1):uint()
        end
        -- Byte-wise unsigned addition truncated to the checksum width (ICD §2).
        local computed = sum % (width == 2 and 65536 or 4294967296)
        local ck = tree:add(f.checksum, tvb(off + HEADER_LEN + length, width))
        local received = tvb(off + HEADER_LEN + length, width):uint()
        if computed ~= received then
            ck:add_proto_expert_info(ex.bad_checksum,
                string.format("Checksum 0x%08x, the bytes sum to 0x%08x (ICD §2)", received, computed))
            ok = false
        end
        tree:add(f.checksum_computed, tvb(off, HEADER_LEN + length), computed):set_generated()
    end
    local version = bit32.rshift(bit32.band(props, 0x7f00), 8)
    if version < IDD_MIN or version > IDD_MAX then
        pt:add_proto_expert_info(ex.bad_version,
            string.format("IDD version %d outside 30..=40: rejected at the wrapper", version))
        ok = false
    end
    if not ok then return nil end

    local next_off = off + total
    if bit32.band(props, 0x0020) ~= 0 then
        -- ICD §9: the trailer follows the checksum in the same datagram.
        if tvb:len() - next_off >= TRAILER_LEN then
            local st = tree:add(tvb(next_off, TRAILER_LEN), "Signature trailer (ICD §9)")
            st:add(f.key_id, tvb(next_off, 1))
            st:add(f.link_id, tvb(next_off + 1, 1))
            st:add(f.trailer_reserved, tvb(next_off + 2, 2))
            st:add(f.signature, tvb(next_off + 4, 12))
            tree:set_len(total + TRAILER_LEN)
            next_off = next_off + TRAILER_LEN
        else
            tree:add_proto_expert_info(ex.no_trailer)
        end
    end
    return next_off
end

function p.dissector(tvb, pinfo, root)
    pinfo.cols.protocol = "STANAG4586"
    local off, index, names = 0, 1, {}
    while off and off < tvb:len() do
        if tvb:len() - off >= 14 then
            local t = tvb(off + 12, 2):uint()
            local m = MESSAGES[t]
            table.insert(names, string.format("#%d %s", t, m and m.name or "?"))
        end
        off = dissect_frame(tvb, pinfo, root, off, index)
        index = index + 1
    end
    if #names > 0 and tvb:len() >= 12 then
        -- Who speaks to whom: the IDs of the first frame (ICD §1 defaults: GCS 0x0A000001, FCC
        -- 0x0B000001).
        pinfo.cols.info = string.format("0x%08x → 0x%08x  %s", tvb(4, 4):uint(), tvb(8, 4):uint(),
            table.concat(names, "; "))
    end
    return tvb:len()
end

-- The wrapper as this project sends it: reserved 0xFFFF, a message type of the ICD, IDD version
-- 30..40, a checksum code that is not 11, a Message Length that fits the datagram.
local function heuristic(tvb, pinfo, root)
    if not p.prefs.heuristic or tvb:len() < HEADER_LEN then return false end
    if tvb(0, 2):uint() ~= 0xffff or MESSAGES[tvb(12, 2):uint()] == nil then return false end
    local props = tvb(14, 2):uint()
    local version = bit32.rshift(bit32.band(props, 0x7f00), 8)
    local code = bit32.rshift(bit32.band(props, 0x00c0), 6)
    local length = tvb(2, 2):uint()
    if version < IDD_MIN or version > IDD_MAX or code == 3 or length == 0 or length > MAX_DATA_LEN then
        return false
    end
    if HEADER_LEN + length > tvb:len() then return false end
    p.dissector(tvb, pinfo, root)
    pinfo.conversation = p
    return true
end

local registered = nil
function p.prefs_changed()
    local udp = DissectorTable.get("udp.port")
    if registered then udp:remove(registered, p) end
    registered = p.prefs.ports
    udp:add(registered, p)
end

DissectorTable.get("udp.port"):add(p.prefs.ports, p)
registered = p.prefs.ports
p:register_heuristic("udp", heuristic)
