//! The contracts for C and Python stay in step with the Rust types (docs/design.md, "Contracts
//! between partitions": a replacement partition in another language opens the same services).
//!
//! Three descriptions of the same contracts are reduced to one list of facts each, one line per
//! fact, and compared:
//!
//! - **Rust**: every payload of `contracts` and the wire newtypes it contains, field by field
//!   with `offset_of!`, `size_of` and `align_of`, each with the iceoryx2 type name of its
//!   `#[type_name(...)]`; the service paths and QoS of [`FccService::ALL`]; the capacities; the
//!   enumerations' values. Each field list is an exhaustive destructuring pattern of the type,
//!   so a field added in Rust and not listed here does not compile, and the fields listed must
//!   cover every byte of the type: no structure has padding (checked here; the bytes alignment
//!   would add are `reserved*` fields, interfaces/src/contracts.rs).
//! - **C**: `interfaces/c/missionlink_contracts.h` is parsed for its structures, their fields
//!   and every `MISSIONLINK_` name it defines; a program generated from that, compiled with `cc`
//!   against the header, prints `sizeof`, `_Alignof` and `offsetof` of everything, the type
//!   names, service paths, QoS numbers, capacities and enumeration values.
//! - **Python**: `python3` imports `interfaces/python/missionlink_contracts.py` and prints the
//!   same of its ctypes structures, service table, constants and enumerations.
//!
//! Any line in one list and not in another fails the test with the lines that differ. Without
//! `cc` or `python3` the test fails and says what to install: it never skips.
//!
//! The values as well as the layouts: a C program makes each empty value of the contracts from
//! the header alone (zero, then what the header says is not zero when nothing is known) and its
//! bytes must be those of the Rust constants (`WaypointListPayload::EMPTY`, ...), reserved
//! bytes included.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use core::fmt::Debug;
use core::mem::{align_of, offset_of, size_of};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use iceoryx2::prelude::ZeroCopySend;
use missionlink_interfaces::capacity::{
    MAX_AREAS, MAX_NO_FLY_ZONES, MAX_POLYGON_VERTICES, MAX_WAYPOINTS, MIN_POLYGON_VERTICES,
};
use missionlink_interfaces::contracts::{
    ABSENT, AreaAltitudes, AreaListPayload, AutomationCommandPayload, AutomationStatePayload,
    CONTRACT_VERSION, CircleArea, DEFAULT_HEARTBEAT_PERIOD, DEFAULT_SERVICE_PREFIX, FccService,
    FlightPhase, FramePayload, GuidanceProgressPayload, HeartbeatPayload, Link, Partition,
    PolygonArea, WaypointEntry, WaypointListPayload,
};
use missionlink_interfaces::wire::{
    Altitude, AltitudeType, Angle, ExecuteCommand, GeoPoint, LegType, MAX_FRAME_LEN, SafetyOffset,
    Speed, SpeedType, TurnDirection, TurnType,
};
use zerocopy::{Immutable, IntoBytes};

/// One field of a structure as Rust lays it out.
struct Field {
    name: &'static str,
    offset: usize,
    size: usize,
    align: usize,
    /// The field's type, paths removed: `u16`, `GeoPoint`, `[u8; 5]`.
    ty: String,
}

/// One structure as Rust lays it out.
struct Layout {
    name: &'static str,
    size: usize,
    align: usize,
    /// The iceoryx2 type name, for the types that declare one (`#[type_name(...)]`).
    type_name: Option<String>,
    fields: Vec<Field>,
}

/// `core::any::type_name` without module paths: `[missionlink_interfaces::wire::msg::GeoPoint;
/// 60]` becomes `[GeoPoint; 60]`.
fn short_type_name(full: &str) -> String {
    let mut out = String::new();
    let mut word = String::new();
    let mut chars = full.chars().peekable();
    while let Some(c) = chars.next() {
        if c == ':' && chars.peek() == Some(&':') {
            chars.next();
            word.clear();
        } else if c.is_alphanumeric() || c == '_' {
            word.push(c);
        } else {
            out.push_str(&word);
            word.clear();
            out.push(c);
        }
    }
    out.push_str(&word);
    out
}

/// `size_of::<T>()`, for a type without padding only: zerocopy's `IntoBytes`, derived on every
/// structure of the contracts, does not hold for a type with padding (contracts.rs), so a
/// structure listed in [`rust_layouts`] without it does not compile.
fn size_without_padding<T: IntoBytes>() -> usize {
    size_of::<T>()
}

fn field_size<T, F>(_: fn(&T) -> &F) -> usize {
    size_of::<F>()
}

fn field_align<T, F>(_: fn(&T) -> &F) -> usize {
    align_of::<F>()
}

fn field_type<T, F>(_: fn(&T) -> &F) -> String {
    short_type_name(core::any::type_name::<F>())
}

/// The iceoryx2 type name of `T`, as a Rust publisher or subscriber announces it.
#[allow(
    unsafe_code,
    reason = "type_name is unsafe only to discourage overriding it"
)]
fn iceoryx2_type_name<T: ZeroCopySend>() -> String {
    // SAFETY: type_name only returns a static string.
    unsafe { <T as ZeroCopySend>::type_name() }.to_owned()
}

/// The layout of a structure with named fields. `named` for the types with an iceoryx2 type
/// name of their own, `plain` for the others. The pattern in the closure lists every field
/// without `..`: a field added to or removed from the type fails to compile here.
macro_rules! layout {
    (@type_name named $t:ident) => {
        Some(iceoryx2_type_name::<$t>())
    };
    (@type_name plain $t:ident) => {
        None
    };
    ($kind:ident $t:ident { $($f:ident),+ $(,)? }) => {{
        let _every_field_is_listed = |v: &$t| {
            let $t { $($f: _),+ } = v;
        };
        Layout {
            name: stringify!($t),
            size: size_without_padding::<$t>(),
            align: align_of::<$t>(),
            type_name: layout!(@type_name $kind $t),
            fields: vec![$(Field {
                name: stringify!($f),
                offset: offset_of!($t, $f),
                size: field_size(|v: &$t| &v.$f),
                align: field_align(|v: &$t| &v.$f),
                ty: field_type(|v: &$t| &v.$f),
            }),+],
        }
    }};
}

/// The layout of a wire newtype: one private field, seen from C and Python as `raw`, the type
/// its `raw()` accessor returns (and of the same size and alignment as the newtype).
macro_rules! newtype {
    ($t:ident) => {{
        fn raw_type<R>(_: fn($t) -> R) -> (usize, usize, String) {
            (
                size_of::<R>(),
                align_of::<R>(),
                short_type_name(core::any::type_name::<R>()),
            )
        }
        let (size, align, ty) = raw_type($t::raw);
        assert_eq!(
            (size_of::<$t>(), align_of::<$t>()),
            (size, align),
            "{} is not laid out as its raw value",
            stringify!($t)
        );
        Layout {
            name: stringify!($t),
            size: size_without_padding::<$t>(),
            align: align_of::<$t>(),
            type_name: None,
            fields: vec![Field {
                name: "raw",
                offset: 0,
                size,
                align,
                ty,
            }],
        }
    }};
}

/// Every structure of the contracts, the wire newtypes first (the order of the C header).
fn rust_layouts() -> Vec<Layout> {
    vec![
        newtype!(Angle),
        newtype!(Altitude),
        newtype!(Speed),
        newtype!(SafetyOffset),
        layout!(plain GeoPoint { latitude, longitude }),
        layout!(named FramePayload {
            origin_ns,
            published_ns,
            sequence,
            len,
            link,
            reserved,
            bytes,
            reserved_tail
        }),
        layout!(named WaypointEntry {
            number,
            next,
            position,
            altitude,
            speed,
            altitude_type,
            speed_type,
            turn_type,
            leg_type,
            rf_turn_direction,
            reserved,
            rf_centre
        }),
        layout!(named WaypointListPayload {
            generation,
            activation,
            take_off_height,
            count,
            initial_waypoint,
            bidirectional,
            reserved0,
            planning_wind,
            reserved,
            waypoints
        }),
        layout!(named AreaAltitudes {
            lower,
            upper,
            has_lower,
            has_upper,
            altitude_type,
            reserved
        }),
        layout!(named PolygonArea {
            area_id,
            vertex_count,
            reserved,
            altitudes,
            vertices
        }),
        layout!(named CircleArea {
            area_id,
            reserved,
            altitudes,
            centre,
            border
        }),
        layout!(named AreaListPayload {
            generation,
            activation,
            safety_offset,
            no_fly_polygon_count,
            no_fly_circle_count,
            reserved,
            fly_zone,
            no_fly_polygons,
            no_fly_circles
        }),
        layout!(named AutomationStatePayload {
            sequence,
            changed_ns,
            flown_waypoint_list,
            flight_phase,
            trajectory_generation_active,
            route_reversed,
            reserved0,
            land_at,
            guidance_alive,
            reserved
        }),
        layout!(named AutomationCommandPayload {
            sequence,
            accepted_ns,
            command,
            reserved
        }),
        layout!(named HeartbeatPayload {
            sequence,
            time_ns,
            period_ns,
            pid,
            reserved
        }),
        layout!(named GuidanceProgressPayload {
            sequence,
            time_ns,
            waypoint_list,
            latitude_deg,
            longitude_deg,
            altitude_m,
            ground_speed_mps,
            from,
            to,
            next,
            in_no_fly_zone,
            inside_fly_zone,
            trajectory_generation_active,
            climb_complete,
            route_complete,
            on_ground,
            reserved,
            heading_deg,
            roll_deg,
            pitch_deg,
            climb_rate_mps
        }),
    ]
}

fn round_up(n: usize, align: usize) -> usize {
    n.div_ceil(align) * align
}

/// Checks that the fields of `layout` cover every byte of it but for alignment padding, and
/// returns the padding as (offset, bytes).
fn padding(layout: &Layout) -> Vec<(usize, usize)> {
    let mut fields: Vec<&Field> = layout.fields.iter().collect();
    fields.sort_by_key(|f| f.offset);
    let mut end = 0;
    let mut gaps = Vec::new();
    for f in fields {
        assert!(
            f.offset >= end,
            "{}.{} at {} overlaps the field before it (ends at {end})",
            layout.name,
            f.name,
            f.offset
        );
        assert_eq!(
            f.offset,
            round_up(end, f.align),
            "{}: bytes {end}..{} are covered by no listed field: list every field",
            layout.name,
            f.offset
        );
        if f.offset > end {
            gaps.push((end, f.offset - end));
        }
        end = f.offset + f.size;
    }
    assert_eq!(
        layout.size,
        round_up(end, layout.align),
        "{}: bytes {end}..{} are covered by no listed field: list every field",
        layout.name,
        layout.size
    );
    if layout.size > end {
        gaps.push((end, layout.size - end));
    }
    gaps
}

/// `OnGround` -> `ON_GROUND`, `WaypointListPayload` -> `WAYPOINT_LIST_PAYLOAD`, `Wgs84` ->
/// `WGS84`: how C and Python spell the Rust names in constants.
fn upper_snake(name: &str) -> String {
    let mut out = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('_');
        }
        out.extend(c.to_uppercase());
    }
    out
}

/// The key of a service in C and Python: its path without `fcc/`, `/` and `-` as `_`,
/// upper case (`fcc/mission/waypoint-list` -> `MISSION_WAYPOINT_LIST`).
fn service_key(service: FccService) -> String {
    service
        .path()
        .trim_start_matches("fcc/")
        .replace(['/', '-'], "_")
        .to_uppercase()
}

/// Every value of an enumeration that crosses shared memory as `u8`, as (name, value).
fn enum_values<T: TryFrom<u8> + Debug>() -> Vec<(String, u8)> {
    (0..=u8::MAX)
        .filter_map(|v| {
            T::try_from(v)
                .ok()
                .map(|e| (upper_snake(&format!("{e:?}")), v))
        })
        .collect()
}

/// The enumerations whose bytes the payloads carry.
fn rust_enums() -> Vec<(&'static str, Vec<(String, u8)>)> {
    vec![
        ("Link", enum_values::<Link>()),
        ("FlightPhase", enum_values::<FlightPhase>()),
        ("ExecuteCommand", enum_values::<ExecuteCommand>()),
        ("AltitudeType", enum_values::<AltitudeType>()),
        ("SpeedType", enum_values::<SpeedType>()),
        ("TurnType", enum_values::<TurnType>()),
        ("LegType", enum_values::<LegType>()),
        ("TurnDirection", enum_values::<TurnDirection>()),
    ]
}

/// A constant's value: a number or a string.
enum Value {
    Number(u64),
    Text(&'static str),
}

/// The constants, by their name in C (after `MISSIONLINK_`) and Python.
fn rust_constants() -> Vec<(&'static str, Value)> {
    let n = |v: usize| Value::Number(v as u64);
    vec![
        (
            "CONTRACT_VERSION",
            Value::Number(u64::from(CONTRACT_VERSION)),
        ),
        (
            "DEFAULT_SERVICE_PREFIX",
            Value::Text(DEFAULT_SERVICE_PREFIX),
        ),
        ("ABSENT", Value::Number(u64::from(ABSENT))),
        (
            "DEFAULT_HEARTBEAT_PERIOD_MS",
            Value::Number(DEFAULT_HEARTBEAT_PERIOD.as_millis() as u64),
        ),
        ("MAX_WAYPOINTS", n(MAX_WAYPOINTS)),
        ("MAX_AREAS", n(MAX_AREAS)),
        ("MAX_NO_FLY_ZONES", n(MAX_NO_FLY_ZONES)),
        ("MAX_POLYGON_VERTICES", n(MAX_POLYGON_VERTICES)),
        ("MIN_POLYGON_VERTICES", n(MIN_POLYGON_VERTICES)),
        ("MAX_FRAME_LEN", n(MAX_FRAME_LEN)),
    ]
}

/// The key of a partition in C and Python (`Guidance` -> `GUIDANCE`).
fn partition_key(p: Partition) -> String {
    upper_snake(&format!("{p:?}"))
}

fn partition_fact(p: Partition) -> String {
    let allowed = p.allowed();
    format!(
        "partition {} role {} binary {} links {} state {}",
        partition_key(p),
        p.role(),
        p.binary(),
        u8::from(allowed.links),
        u8::from(allowed.state)
    )
}

fn service_fact(service: FccService) -> String {
    let q = service.qos();
    format!(
        "service {} path {} history {} buffer {} publishers {} subscribers {} listeners {} safe_overflow {}",
        service_key(service),
        service.path(),
        q.history_size,
        q.subscriber_max_buffer_size,
        q.max_publishers,
        q.max_subscribers,
        q.max_listeners(),
        u8::from(q.safe_overflow)
    )
}

/// The facts of the Rust types; every other description must give the same.
fn rust_facts(layouts: &[Layout]) -> BTreeSet<String> {
    let mut facts = BTreeSet::new();
    for l in layouts {
        facts.insert(format!(
            "struct {} size {} align {}",
            l.name, l.size, l.align
        ));
        if let Some(t) = &l.type_name {
            facts.insert(format!("type_name {} {t}", l.name));
        }
        for (i, f) in l.fields.iter().enumerate() {
            facts.insert(format!(
                "field {} {i} {} offset {} size {} type {}",
                l.name, f.name, f.offset, f.size, f.ty
            ));
        }
    }
    for (name, value) in rust_constants() {
        facts.insert(match value {
            Value::Number(v) => format!("const {name} {v}"),
            Value::Text(t) => format!("const {name} {t}"),
        });
    }
    for service in FccService::ALL {
        facts.insert(service_fact(service));
    }
    for p in Partition::ALL {
        facts.insert(partition_fact(p));
    }
    for (name, values) in rust_enums() {
        for (variant, v) in values {
            facts.insert(format!("enum {name} {variant} {v}"));
        }
    }
    facts
}

/// The lines only in `ours` and only in `theirs`, for a failure message.
fn differences(what: &str, ours: &BTreeSet<String>, theirs: &BTreeSet<String>) -> Option<String> {
    let missing: Vec<_> = ours.difference(theirs).collect();
    let extra: Vec<_> = theirs.difference(ours).collect();
    if missing.is_empty() && extra.is_empty() {
        return None;
    }
    let mut text = format!("{what} differs from the Rust types\n");
    for m in missing {
        text.push_str(&format!("  Rust only:      {m}\n"));
    }
    for e in extra {
        text.push_str(&format!("  {what:<14.14}  {e}\n"));
    }
    Some(text)
}

fn interfaces_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A directory of this test run's own for `what` (the tests of this file run in parallel, and
/// each removes its directory when done).
fn scratch_dir(what: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "missionlink-contracts-{}-{what}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `command`, failing with `missing` when the program is not there.
fn output(command: &mut Command, missing: &str) -> std::process::Output {
    match command.output() {
        Ok(out) => out,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => panic!("{missing}"),
        Err(e) => panic!("cannot run {command:?}: {e}"),
    }
}

// ---------------------------------------------------------------------------------------------
// C
// ---------------------------------------------------------------------------------------------

/// A structure of the header: its name and its fields as (C type, name, array length token).
struct CStruct {
    name: String,
    fields: Vec<(String, String, Option<String>)>,
}

/// What the header declares: its structures, in order, and every `MISSIONLINK_` name it
/// defines (macros and enumeration constants).
struct CHeader {
    structs: Vec<CStruct>,
    names: BTreeSet<String>,
}

/// Removes `/* ... */` comments on one line.
fn strip_comment(line: &str) -> &str {
    line.split("/*").next().unwrap_or_default().trim()
}

/// Parses the header as it is written (one declaration per line); a line in a structure that
/// is not `TYPE NAME;` or `TYPE NAME[N];` fails the test.
fn parse_header(text: &str) -> CHeader {
    let mut structs = Vec::new();
    let mut names = BTreeSet::new();
    let mut current: Option<CStruct> = None;
    for raw in text.lines() {
        let line = strip_comment(raw);
        if let Some(rest) = line.strip_prefix("#define ") {
            let name = rest.split_whitespace().next().unwrap_or_default();
            if name.starts_with("MISSIONLINK_") {
                names.insert(name.to_owned());
            }
            continue;
        }
        if line.starts_with("MISSIONLINK_") && line.contains('=') {
            names.insert(line.split('=').next().unwrap().trim().to_owned());
            continue;
        }
        if let Some(rest) = line.strip_prefix("typedef struct ") {
            let name = rest.trim_end_matches('{').trim().to_owned();
            current = Some(CStruct {
                name,
                fields: Vec::new(),
            });
            continue;
        }
        let Some(s) = current.as_mut() else { continue };
        if let Some(rest) = line.strip_prefix('}') {
            assert_eq!(
                rest.trim().trim_end_matches(';').trim(),
                s.name,
                "the header's typedef of {} ends with another name",
                s.name
            );
            structs.push(current.take().unwrap());
            continue;
        }
        if line.is_empty() {
            continue;
        }
        let decl = line
            .strip_suffix(';')
            .unwrap_or_else(|| panic!("in struct {} of the header: {raw:?} is no field", s.name));
        let parts: Vec<&str> = decl.split_whitespace().collect();
        let [ty, declarator] = parts[..] else {
            panic!(
                "in struct {} of the header: {raw:?} is not TYPE NAME;",
                s.name
            );
        };
        let (name, len) = match declarator.split_once('[') {
            Some((name, len)) => (name, Some(len.trim_end_matches(']').to_owned())),
            None => (declarator, None),
        };
        s.fields.push((ty.to_owned(), name.to_owned(), len));
    }
    assert!(current.is_none(), "a structure of the header is not closed");
    CHeader { structs, names }
}

/// The Rust spelling of a C field type.
fn rust_type_of_c(ty: &str) -> &str {
    match ty {
        "uint8_t" => "u8",
        "uint16_t" => "u16",
        "uint32_t" => "u32",
        "uint64_t" => "u64",
        "int8_t" => "i8",
        "int16_t" => "i16",
        "int32_t" => "i32",
        "int64_t" => "i64",
        "double" => "f64",
        "float" => "f32",
        other => other,
    }
}

/// The `MISSIONLINK_` names the header must define, no more and no fewer.
fn expected_c_names(layouts: &[Layout]) -> BTreeSet<String> {
    let mut names = BTreeSet::from(["MISSIONLINK_CONTRACTS_H".to_owned()]);
    for (name, _) in rust_constants() {
        names.insert(format!("MISSIONLINK_{name}"));
    }
    for service in FccService::ALL {
        let key = service_key(service);
        for what in [
            "PATH",
            "HISTORY_SIZE",
            "SUBSCRIBER_MAX_BUFFER_SIZE",
            "MAX_PUBLISHERS",
            "MAX_SUBSCRIBERS",
            "MAX_LISTENERS",
            "SAFE_OVERFLOW",
        ] {
            names.insert(format!("MISSIONLINK_SERVICE_{key}_{what}"));
        }
    }
    for (name, values) in rust_enums() {
        for (variant, _) in values {
            names.insert(format!("MISSIONLINK_{}_{variant}", upper_snake(name)));
        }
    }
    for p in Partition::ALL {
        for what in ["ROLE", "BINARY", "LINKS", "STATE"] {
            names.insert(format!("MISSIONLINK_PARTITION_{}_{what}", partition_key(p)));
        }
    }
    for l in layouts.iter().filter(|l| l.type_name.is_some()) {
        names.insert(format!("MISSIONLINK_{}_TYPE_NAME", upper_snake(l.name)));
    }
    names
}

/// A C string literal of `s` (plain ASCII names only).
fn c_str(s: &str) -> String {
    assert!(
        s.chars()
            .all(|c| c.is_ascii_graphic() && c != '"' && c != '\\')
    );
    format!("\"{s}\"")
}

/// The program that prints the header's facts.
fn c_program(header: &CHeader, layouts: &[Layout]) -> String {
    let mut p = String::from(
        "#include <stddef.h>\n#include <stdio.h>\n#include \"missionlink_contracts.h\"\n\n\
         int main(void) {\n",
    );
    for s in &header.structs {
        let n = &s.name;
        p.push_str(&format!(
            "    printf(\"struct %s size %zu align %zu\\n\", {}, sizeof({n}), _Alignof({n}));\n",
            c_str(n)
        ));
        for (i, (ty, field, len)) in s.fields.iter().enumerate() {
            let member = format!("((const {n} *)0)->{field}");
            let ty = rust_type_of_c(ty);
            let (format, count) = match len {
                Some(_) => (
                    format!("[{ty}; %zu]"),
                    format!(", sizeof({member}) / sizeof({member}[0])"),
                ),
                None => (ty.to_owned(), String::new()),
            };
            p.push_str(&format!(
                "    printf(\"field %s {i} %s offset %zu size %zu type {format}\\n\", {}, {}, \
                 offsetof({n}, {field}), sizeof({member}){count});\n",
                c_str(n),
                c_str(field)
            ));
        }
    }
    for l in layouts.iter().filter(|l| l.type_name.is_some()) {
        p.push_str(&format!(
            "    printf(\"type_name %s %s\\n\", {}, MISSIONLINK_{}_TYPE_NAME);\n",
            c_str(l.name),
            upper_snake(l.name)
        ));
    }
    for (name, value) in rust_constants() {
        let (format, arg) = match value {
            Value::Number(_) => ("%llu", format!("(unsigned long long)(MISSIONLINK_{name})")),
            Value::Text(_) => ("%s", format!("MISSIONLINK_{name}")),
        };
        p.push_str(&format!(
            "    printf(\"const %s {format}\\n\", {}, {arg});\n",
            c_str(name)
        ));
    }
    for service in FccService::ALL {
        let m = format!("MISSIONLINK_SERVICE_{}", service_key(service));
        p.push_str(&format!(
            "    printf(\"service %s path %s history %d buffer %d publishers %d subscribers %d \
             listeners %d safe_overflow %d\\n\", {}, {m}_PATH, {m}_HISTORY_SIZE, \
             {m}_SUBSCRIBER_MAX_BUFFER_SIZE, {m}_MAX_PUBLISHERS, {m}_MAX_SUBSCRIBERS, \
             {m}_MAX_LISTENERS, {m}_SAFE_OVERFLOW);\n",
            c_str(&service_key(service))
        ));
    }
    for partition in Partition::ALL {
        let m = format!("MISSIONLINK_PARTITION_{}", partition_key(partition));
        p.push_str(&format!(
            "    printf(\"partition %s role %s binary %s links %d state %d\\n\", {}, {m}_ROLE, \
             {m}_BINARY, {m}_LINKS, {m}_STATE);\n",
            c_str(&partition_key(partition))
        ));
    }
    for (name, values) in rust_enums() {
        for (variant, _) in values {
            p.push_str(&format!(
                "    printf(\"enum %s %s %d\\n\", {}, {}, (int)MISSIONLINK_{}_{variant});\n",
                c_str(name),
                c_str(&variant),
                upper_snake(name)
            ));
        }
    }
    p.push_str("    return 0;\n}\n");
    p
}

/// The facts of the C header, from a program compiled with `cc` against it.
fn c_facts(layouts: &[Layout]) -> BTreeSet<String> {
    let header_path = c_header_path();
    let text = std::fs::read_to_string(&header_path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", header_path.display()));
    let header = parse_header(&text);
    let expected = expected_c_names(layouts);
    let missing: Vec<_> = expected.difference(&header.names).collect();
    let extra: Vec<_> = header.names.difference(&expected).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "{} defines other MISSIONLINK_ names than the Rust contracts have:\n  missing: \
         {missing:?}\n  not in Rust: {extra:?}",
        header_path.display()
    );

    run_c("layout", &c_program(&header, layouts))
        .lines()
        .map(str::to_owned)
        .collect()
}

/// The C header.
fn c_header_path() -> PathBuf {
    interfaces_dir().join("c").join("missionlink_contracts.h")
}

/// Compiles `program` against the header with `cc` (strict C11, every warning an error), runs
/// it and returns what it printed.
fn run_c(name: &str, program: &str) -> String {
    let header_path = c_header_path();
    let dir = scratch_dir(name);
    let source = dir.join(format!("{name}.c"));
    let executable = dir.join(name);
    std::fs::write(&source, program).unwrap();
    let compiled = output(
        Command::new("cc")
            .args([
                "-std=c11",
                "-Wall",
                "-Wextra",
                "-Wpedantic",
                "-Werror",
                "-I",
            ])
            .arg(header_path.parent().unwrap())
            .arg(&source)
            .arg("-o")
            .arg(&executable),
        "the contracts test compiles the C header with `cc`, which is not installed: install a \
         C compiler (Debian: apt-get install gcc)",
    );
    assert!(
        compiled.status.success(),
        "cc could not compile {} against {}:\n{}",
        source.display(),
        header_path.display(),
        String::from_utf8_lossy(&compiled.stderr)
    );
    let run = output(
        &mut Command::new(&executable),
        "the compiled program is gone",
    );
    assert!(run.status.success(), "{run:?}");
    let _ = std::fs::remove_dir_all(&dir);
    String::from_utf8(run.stdout).unwrap()
}

/// The empty values of the contracts as a C partition makes them from the header alone: the
/// structure set to zero, then the fields the header says are not zero when nothing is known
/// (an optional enumeration byte holds MISSIONLINK_ABSENT; guidance's four floats are NaN
/// before anything is flown, on the ground). It prints each one's bytes in hex, one line each:
/// `<name> <hex>`, in the order of [`rust_empty_values`].
const C_EMPTY_VALUES: &str = r#"
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "missionlink_contracts.h"

static void print(const char *name, const void *value, size_t size) {
    const unsigned char *b = value;
    printf("%s ", name);
    for (size_t i = 0; i < size; i++) {
        printf("%02x", b[i]);
    }
    printf("\n");
}

static void no_altitudes(AreaAltitudes *a) {
    a->altitude_type = MISSIONLINK_ABSENT;
}

static void empty_waypoint(WaypointEntry *w) {
    w->altitude_type = MISSIONLINK_ABSENT;
    w->speed_type = MISSIONLINK_ABSENT;
    w->rf_turn_direction = MISSIONLINK_ABSENT;
}

static void empty_polygon(PolygonArea *p) {
    no_altitudes(&p->altitudes);
}

static void empty_circle(CircleArea *c) {
    no_altitudes(&c->altitudes);
}

/* Static: the lists are kilobytes. Each is set to zero before use all the same. */
static FramePayload frame;
static WaypointEntry waypoint;
static WaypointListPayload waypoints;
static AreaAltitudes altitudes;
static PolygonArea polygon;
static CircleArea circle;
static AreaListPayload areas;
static AutomationStatePayload state;
static GuidanceProgressPayload progress;

#define ZERO(v) memset(&(v), 0, sizeof(v))

int main(void) {
    ZERO(frame);
    frame.link = MISSIONLINK_LINK_DIRECT;
    print("FramePayload", &frame, sizeof frame);

    ZERO(waypoint);
    empty_waypoint(&waypoint);
    print("WaypointEntry", &waypoint, sizeof waypoint);

    ZERO(waypoints);
    for (size_t i = 0; i < MISSIONLINK_MAX_WAYPOINTS; i++) {
        empty_waypoint(&waypoints.waypoints[i]);
    }
    print("WaypointListPayload", &waypoints, sizeof waypoints);

    ZERO(altitudes);
    no_altitudes(&altitudes);
    print("AreaAltitudes", &altitudes, sizeof altitudes);

    ZERO(polygon);
    empty_polygon(&polygon);
    print("PolygonArea", &polygon, sizeof polygon);

    ZERO(circle);
    empty_circle(&circle);
    print("CircleArea", &circle, sizeof circle);

    ZERO(areas);
    empty_polygon(&areas.fly_zone);
    for (size_t i = 0; i < MISSIONLINK_MAX_NO_FLY_ZONES; i++) {
        empty_polygon(&areas.no_fly_polygons[i]);
        empty_circle(&areas.no_fly_circles[i]);
    }
    print("AreaListPayload", &areas, sizeof areas);

    ZERO(state);
    state.flight_phase = MISSIONLINK_FLIGHT_PHASE_ON_GROUND;
    print("AutomationStatePayload", &state, sizeof state);

    ZERO(progress);
    progress.on_ground = true;
    progress.heading_deg = NAN;
    progress.roll_deg = NAN;
    progress.pitch_deg = NAN;
    progress.climb_rate_mps = NAN;
    print("GuidanceProgressPayload", &progress, sizeof progress);
    return 0;
}
"#;

/// The bytes of `value` in hex. `IntoBytes`: every byte is a field's (there is no padding to
/// read).
fn hex<T: IntoBytes + Immutable>(value: &T) -> String {
    value
        .as_bytes()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The empty values Rust defines (the constants, and a frame payload of no frame), as
/// `<name> <hex>` in the order of [`C_EMPTY_VALUES`].
fn rust_empty_values() -> Vec<String> {
    let frame = FramePayload::new(Link::Direct, &[], 0).unwrap();
    [
        ("FramePayload", hex(&frame)),
        ("WaypointEntry", hex(&WaypointEntry::EMPTY)),
        ("WaypointListPayload", hex(&WaypointListPayload::EMPTY)),
        ("AreaAltitudes", hex(&AreaAltitudes::NONE)),
        ("PolygonArea", hex(&PolygonArea::EMPTY)),
        ("CircleArea", hex(&CircleArea::EMPTY)),
        ("AreaListPayload", hex(&AreaListPayload::EMPTY)),
        (
            "AutomationStatePayload",
            hex(&AutomationStatePayload::ON_GROUND),
        ),
        (
            "GuidanceProgressPayload",
            hex(&GuidanceProgressPayload::IDLE),
        ),
    ]
    .into_iter()
    .map(|(name, bytes)| format!("{name} {bytes}"))
    .collect()
}

// ---------------------------------------------------------------------------------------------
// Python
// ---------------------------------------------------------------------------------------------

/// Prints the facts of the Python module (its directory is the first argument). Every
/// structure, service, constant and enumeration the module defines is listed, so one it has
/// and Rust has not shows as well as one it lacks.
const PYTHON_FACTS: &str = r#"
import ctypes, enum, inspect, sys
sys.path.insert(0, sys.argv[1])
import missionlink_contracts as m

SIMPLE = {
    ctypes.c_uint8: "u8", ctypes.c_uint16: "u16", ctypes.c_uint32: "u32",
    ctypes.c_uint64: "u64", ctypes.c_int8: "i8", ctypes.c_int16: "i16",
    ctypes.c_int32: "i32", ctypes.c_int64: "i64", ctypes.c_bool: "bool",
    ctypes.c_double: "f64", ctypes.c_float: "f32",
}

def type_of(t):
    if isinstance(t, type) and issubclass(t, ctypes.Array):
        return "[%s; %d]" % (type_of(t._type_), t._length_)
    if isinstance(t, type) and issubclass(t, ctypes.Structure):
        return t.__name__
    return SIMPLE.get(t, "unknown ctypes type %r" % (t,))

def ours(obj):
    return getattr(obj, "__module__", None) == m.__name__

for name, cls in inspect.getmembers(m, inspect.isclass):
    if issubclass(cls, ctypes.Structure) and ours(cls):
        print("struct %s size %d align %d" % (cls.__name__, ctypes.sizeof(cls), ctypes.alignment(cls)))
        if hasattr(cls, "type_name"):
            print("type_name %s %s" % (cls.__name__, cls.type_name()))
        for i, (field, t) in enumerate(cls._fields_):
            d = getattr(cls, field)
            print("field %s %d %s offset %d size %d type %s" % (cls.__name__, i, field, d.offset, d.size, type_of(t)))
    elif issubclass(cls, enum.IntEnum) and ours(cls):
        for member in cls:
            print("enum %s %s %d" % (cls.__name__, member.name, member.value))

services = []
for name, value in vars(m).items():
    if name.startswith("_"):
        continue
    if isinstance(value, m.Service):
        if not name.startswith("SERVICE_"):
            print("a Service not named SERVICE_*: %s" % name)
        services.append(value)
        q = value.qos
        print("service %s path %s history %d buffer %d publishers %d subscribers %d listeners %d safe_overflow %d"
              % (name[len("SERVICE_"):], value.path, q.history_size, q.subscriber_max_buffer_size,
                 q.max_publishers, q.max_subscribers, q.max_listeners, int(q.safe_overflow)))
    elif isinstance(value, m.Partition):
        if not name.startswith("PARTITION_"):
            print("a Partition not named PARTITION_*: %s" % name)
        print("partition %s role %s binary %s links %d state %d"
              % (name[len("PARTITION_"):], value.role, value.binary, int(value.links), int(value.state)))
    elif name.isupper() and isinstance(value, (int, str)) and not isinstance(value, (bool, enum.Enum)):
        print("const %s %s" % (name, value))
if [p for n, p in vars(m).items() if n.startswith("PARTITION_")] != list(m.PARTITIONS):
    print("PARTITIONS lists other partitions than the PARTITION_* names, or in another order")
if sorted(services) != sorted(m.SERVICES):
    print("SERVICES lists other services than the SERVICE_* names")
structures = [c for c in vars(m).values() if inspect.isclass(c) and issubclass(c, ctypes.Structure) and ours(c)]
if sorted(c.__name__ for c in structures) != sorted(c.__name__ for c in m.STRUCTURES):
    print("STRUCTURES lists other structures than the module defines")
"#;

/// The Python interpreter: `MISSIONLINK_PYTHON` where `tools/test` set it, else `python3` (the
/// module needs nothing but the standard library).
fn python() -> std::ffi::OsString {
    std::env::var_os("MISSIONLINK_PYTHON").unwrap_or_else(|| "python3".into())
}

/// The facts of the Python module, printed by `python3`.
fn python_facts() -> BTreeSet<String> {
    let dir = interfaces_dir().join("python");
    let run = output(
        Command::new(python()).arg("-c").arg(PYTHON_FACTS).arg(&dir),
        "the contracts test runs `python3`, which is not installed: install Python 3 (Debian: \
         apt-get install python3)",
    );
    assert!(
        run.status.success(),
        "python3 could not describe {}:\n{}",
        dir.join("missionlink_contracts.py").display(),
        String::from_utf8_lossy(&run.stderr)
    );
    String::from_utf8(run.stdout)
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The tests
// ---------------------------------------------------------------------------------------------

#[test]
fn the_listed_fields_cover_every_byte_of_each_structure_with_no_padding() {
    // No padding in any structure (contracts.rs): what alignment would add is a `reserved*`
    // field, so C and Python see those bytes as fields too, and the fact lists compare them.
    for layout in rust_layouts() {
        let gaps = padding(&layout);
        assert!(
            gaps.is_empty(),
            "{} ({} bytes): padding at (offset, bytes) {gaps:?}: make it a reserved field",
            layout.name,
            layout.size
        );
    }
}

#[test]
fn every_payload_carries_the_contract_version_in_its_type_name() {
    let layouts = rust_layouts();
    let named: Vec<_> = layouts.iter().filter(|l| l.type_name.is_some()).collect();
    assert_eq!(named.len(), 11);
    for l in named {
        assert_eq!(
            l.type_name.as_deref(),
            Some(format!("missionlink::{}/v{CONTRACT_VERSION}", l.name).as_str())
        );
    }
}

#[test]
fn the_c_header_matches_the_rust_types() {
    let layouts = rust_layouts();
    let rust = rust_facts(&layouts);
    let c = c_facts(&layouts);
    if let Some(diff) = differences("C header", &rust, &c) {
        panic!("{diff}");
    }
    eprintln!("C header: {} facts agree with Rust", c.len());
}

#[test]
fn the_python_module_matches_the_rust_types() {
    let rust = rust_facts(&rust_layouts());
    let python = python_facts();
    if let Some(diff) = differences("Python module", &rust, &python) {
        panic!("{diff}");
    }
    eprintln!("Python module: {} facts agree with Rust", python.len());
}

#[test]
fn the_empty_values_are_the_bytes_a_c_partition_makes_from_the_header() {
    // Every byte of a payload crosses hosts as it is (ICD §14), so the Rust constants must be
    // what a partition in C starts from: zero but where the header says otherwise. A reserved
    // byte a constant left non-zero, or a field that is not zero when nothing is known and
    // that the header does not say so of, shows here as the first byte that differs.
    let c: Vec<String> = run_c("empty", C_EMPTY_VALUES)
        .lines()
        .map(str::to_owned)
        .collect();
    let rust = rust_empty_values();
    assert_eq!(c.len(), rust.len(), "the C program printed {c:?}");
    for (r, c) in rust.iter().zip(&c) {
        let (name, r) = r.split_once(' ').unwrap();
        let (c_name, c) = c.split_once(' ').unwrap();
        assert_eq!(
            name, c_name,
            "the C program prints its values in another order"
        );
        assert_eq!(r.len(), c.len(), "{name}: Rust and C differ in size");
        if let Some(at) = r.bytes().zip(c.bytes()).position(|(a, b)| a != b) {
            // Two hex digits a byte; show eight bytes from the first that differs.
            let byte = at / 2;
            let from = |hex: &str| -> String {
                hex.get(byte * 2..)
                    .unwrap_or_default()
                    .chars()
                    .take(16)
                    .collect()
            };
            panic!(
                "{name}: Rust and C differ from byte {byte}: Rust {}..., C {}...",
                from(r),
                from(c)
            );
        }
    }
}

#[test]
fn the_fact_lists_see_a_difference() {
    // The comparison itself: one changed offset shows as one line on each side.
    let rust = rust_facts(&rust_layouts());
    let mut other = rust.clone();
    let line = rust
        .iter()
        .find(|l| l.starts_with("field GuidanceProgressPayload 7 from "))
        .unwrap()
        .clone();
    other.remove(&line);
    other.insert(line.replace("offset 56", "offset 58"));
    let diff = differences("C header", &rust, &other).unwrap();
    assert_eq!(diff.lines().count(), 3, "{diff}");
    assert!(differences("C header", &rust, &rust).is_none());
}

#[test]
fn names_are_spelled_alike_in_c_and_python() {
    assert_eq!(upper_snake("OnGround"), "ON_GROUND");
    assert_eq!(upper_snake("Wgs84"), "WGS84");
    assert_eq!(upper_snake("WaypointListPayload"), "WAYPOINT_LIST_PAYLOAD");
    assert_eq!(
        service_key(FccService::WaypointList),
        "MISSION_WAYPOINT_LIST"
    );
    assert_eq!(
        short_type_name("[missionlink_interfaces::wire::msg::GeoPoint; 60]"),
        "[GeoPoint; 60]"
    );
    let header = parse_header(
        "#define MISSIONLINK_X 1\ntypedef struct A {\n    uint8_t b[MISSIONLINK_X]; /* c */\n    \
         GeoPoint d;\n} A;\nenum E {\n    MISSIONLINK_E_F = 0\n};\n",
    );
    assert_eq!(header.structs.len(), 1);
    assert_eq!(
        header.structs[0].fields,
        [
            ("uint8_t".into(), "b".into(), Some("MISSIONLINK_X".into())),
            ("GeoPoint".into(), "d".into(), None)
        ]
    );
    assert_eq!(
        header.names,
        BTreeSet::from(["MISSIONLINK_X".into(), "MISSIONLINK_E_F".into()])
    );
    assert!(Path::new(&interfaces_dir().join("c")).is_dir());
}
