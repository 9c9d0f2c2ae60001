//! What a frame holds, as `docs/icd.md` writes it under each example frame: one `(key, value)`
//! pair per wrapper field, the project's one-line summary of the message, and one pair per
//! present field, named as the field tables of ICD §4 name it, in physical units with the raw
//! wire value of scaled fields.

use missionlink_interfaces::wire::{
    Altitude, Angle, AreaShape, Frame, GeoPoint, Message, SafetyOffset, SpecificData, Speed, Text,
    Timestamp, Velocity, WindowOrChecksum,
};

/// The pairs a frame decodes to: the wrapper (ICD §2), the trailer of a signed frame (§9),
/// the summary, and every present field (§4). Panics when the frame does not decode.
pub fn describe(frame: &Frame<'_>) -> Vec<(String, String)> {
    let p = frame.properties();
    let width = p.checksum_width().expect("checksum width");
    let bytes = frame.as_bytes();
    let checksum = &bytes[bytes.len() - width.len()..];
    let mut out = vec![
        kv("Message Length", frame.data().len()),
        kv("Source ID", format!("0x{:08X}", frame.source_id())),
        kv(
            "Destination ID",
            format!("0x{:08X}", frame.destination_id()),
        ),
        kv("Message Type", frame.message_type()),
        kv(
            "Message Properties",
            format!(
                "0x{:04X}: ack {}, IDD {}, checksum {} bytes, {}",
                p.0,
                if p.ack_requested() {
                    "requested"
                } else {
                    "not requested"
                },
                p.idd_version(),
                width.len(),
                if p.signed() { "signed" } else { "not signed" },
            ),
        ),
        kv("Checksum", format!("0x{}", hex(checksum))),
    ];
    if let Some(t) = frame.trailer() {
        out.push(kv("Key ID", t.key_id));
        let link = match t.link_id {
            0 => "0 direct",
            1 => "1 LTE",
            _ => "other",
        };
        out.push(kv("Link ID", link));
        out.push(kv("Reserved", t.reserved.get()));
        out.push(kv("Signature", format!("0x{}", hex(&t.signature))));
    }
    let message = frame.message().expect("the example decodes");
    let pv_len = pv_bytes(&message);
    out.push(kv(
        "Presence Vector",
        format!("0x{}", hex(&frame.data()[..pv_len])),
    ));
    out.push(kv("Summary", &message));
    out.extend(fields(&message));
    out
}

/// Bytes of the presence vector of `message`'s type (ICD §4: U1, U2 or U3).
pub fn pv_bytes(message: &Message) -> usize {
    use missionlink_interfaces::wire::MessageBody as B;
    use missionlink_interfaces::wire::*;
    match message {
        Message::MessageAcknowledgement(_) => MessageAcknowledgement::PV_BYTES,
        Message::MissionTransferCommand(_) => MissionTransferCommand::PV_BYTES,
        Message::UaRoute(_) => <UaRoute as B>::PV_BYTES,
        Message::UaPositionWaypoint(_) => UaPositionWaypoint::PV_BYTES,
        Message::VehicleSpecificWaypoint(_) => VehicleSpecificWaypoint::PV_BYTES,
        Message::MissionUploadDownloadStatus(_) => MissionUploadDownloadStatus::PV_BYTES,
        Message::FromToNext(_) => FromToNext::PV_BYTES,
        Message::InertialStates(_) => InertialStates::PV_BYTES,
        Message::AreaTransmissionCommand(_) => AreaTransmissionCommand::PV_BYTES,
        Message::AreaPolygonLoopSegment(_) => AreaPolygonLoopSegment::PV_BYTES,
        Message::AreaStatusAlert(_) => AreaStatusAlert::PV_BYTES,
        Message::AreaTransmissionStatus(_) => AreaTransmissionStatus::PV_BYTES,
        Message::MissionExecuteCommand(_) => MissionExecuteCommand::PV_BYTES,
        Message::MissionReport(_) => MissionReport::PV_BYTES,
    }
}

fn kv(key: &str, value: impl ToString) -> (String, String) {
    (key.to_string(), value.to_string())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02X}")).collect()
}

fn ts(t: Timestamp) -> String {
    format!("{t} ({} ms)", t.millis())
}

fn angle(a: Angle) -> String {
    format!("{:.7} deg (BAM4 {})", a.degrees(), a.raw())
}

fn alt(a: Altitude) -> String {
    format!("{:.2} m (ALT3 {})", a.metres(), a.raw())
}

fn speed(s: Speed) -> String {
    format!("{:.1} m/s (SPD2 {})", s.mps(), s.raw())
}

fn velocity(v: Velocity) -> String {
    format!("{:.2} m/s (VEL2 {})", v.mps(), v.raw())
}

fn offset(o: SafetyOffset) -> String {
    format!("{:.1} m (raw {})", o.metres(), o.raw())
}

fn text<const N: usize>(t: &Text<N>) -> String {
    format!("{:?}", t.as_str())
}

fn point(p: &GeoPoint) -> String {
    format!("{:.7} {:.7}", p.latitude.degrees(), p.longitude.degrees())
}

/// Pushes `(name, f(value))` when `value` is present.
fn opt<T>(out: &mut Vec<(String, String)>, name: &str, value: Option<T>, f: impl Fn(T) -> String) {
    if let Some(v) = value {
        out.push(kv(name, f(v)));
    }
}

/// The present fields of `message`, by the names of its ICD table. Exhaustive: a message type
/// added to the code must say here how its fields read.
pub fn fields(message: &Message) -> Vec<(String, String)> {
    let mut o = Vec::new();
    match message {
        Message::MessageAcknowledgement(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Original Message Time Stamp", ts(m.original_time_stamp)));
            o.push(kv("Original Message Type", m.original_message_type));
            o.push(kv("Acknowledgement Type", m.ack_type.numbered()));
            opt(&mut o, "Reject Reason", m.reject_reason, |r| {
                format!("{} {r:?}", r as u8)
            });
        }
        Message::MissionTransferCommand(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            opt(&mut o, "Mission ID", m.mission_id.as_ref(), text);
            o.push(kv("Mission Plan Mode", m.mode.numbered()));
            opt(&mut o, "Waypoint Number", m.waypoint_number, |n| {
                n.to_string()
            });
            opt(&mut o, "Route ID", m.route_id.as_ref(), text);
            opt(&mut o, "Activity ID", m.activity_id, |a| {
                a.get().to_string()
            });
            opt(&mut o, "Transfer Window", m.transfer_window, |w| {
                w.to_string()
            });
            opt(&mut o, "Mission Checksum", m.mission_checksum, |c| {
                c.to_string()
            });
        }
        Message::UaRoute(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Initial Waypoint Number", m.initial_waypoint));
            opt(&mut o, "Route ID", m.route_id.as_ref(), text);
            opt(&mut o, "Route Type", m.route_type, |t| {
                t.numbered().to_string()
            });
            o.push(kv(
                "Activity ID",
                if m.bidirectional {
                    "1 (bit 0: bidirectional)"
                } else {
                    "0 (one-way)"
                },
            ));
        }
        Message::UaPositionWaypoint(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Waypoint Number", m.waypoint_number));
            o.push(kv("Waypoint to Latitude", angle(m.latitude)));
            o.push(kv("Waypoint to Longitude", angle(m.longitude)));
            opt(&mut o, "Location Type", m.location_type, |t| {
                t.numbered().to_string()
            });
            o.push(kv("Waypoint to Altitude", alt(m.altitude)));
            opt(&mut o, "Waypoint Altitude Type", m.altitude_type, |t| {
                t.numbered().to_string()
            });
            opt(
                &mut o,
                "Altitude Change Behaviour",
                m.altitude_change_behaviour,
                |v| v.to_string(),
            );
            o.push(kv("Waypoint to Speed", speed(m.speed)));
            opt(&mut o, "Waypoint Speed Type", m.speed_type, |t| {
                t.numbered().to_string()
            });
            o.push(kv("Next Waypoint", m.next_waypoint));
            o.push(kv("Turn Type", m.turn_type.numbered()));
            opt(
                &mut o,
                "Optional Messages for Waypoint",
                m.optional_messages,
                |v| format!("0x{v:02X}"),
            );
            o.push(kv("Waypoint Type", m.leg_type.numbered()));
            opt(&mut o, "Limit Type", m.limit_type, |v| v.to_string());
            opt(&mut o, "Loop Limit", m.loop_limit, |v| v.to_string());
            opt(&mut o, "Arrival Time", m.arrival_time, ts);
            opt(&mut o, "Activity ID", m.activity_id, |a| {
                a.get().to_string()
            });
        }
        Message::VehicleSpecificWaypoint(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            match m.data {
                SpecificData::TakeOffHeight { height } => {
                    o.push(kv("Waypoint Number", 0));
                    o.push(kv("Specific Data Type", "1 take-off height"));
                    o.push(kv("Take-off Height", alt(height)));
                }
                SpecificData::RfCentre {
                    waypoint_number,
                    latitude,
                    longitude,
                    turn_direction,
                } => {
                    o.push(kv("Waypoint Number", waypoint_number));
                    o.push(kv("Specific Data Type", "2 radius-to-fix centre"));
                    o.push(kv("RF Centre Latitude", angle(latitude)));
                    o.push(kv("RF Centre Longitude", angle(longitude)));
                    o.push(kv("Turn Direction", turn_direction.numbered()));
                }
            }
            opt(&mut o, "Activity ID", m.activity_id, |a| {
                a.get().to_string()
            });
        }
        Message::MissionUploadDownloadStatus(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            opt(&mut o, "Mission ID", m.mission_id.as_ref(), text);
            o.push(kv("Status", m.status.numbered()));
            opt(&mut o, "Percent Complete", m.percent_complete, |v| {
                v.to_string()
            });
            opt(&mut o, "Waypoint Request", m.waypoint_request, |v| {
                v.to_string()
            });
            opt(&mut o, "Mission Plan Mode", m.mode, |v| {
                v.numbered().to_string()
            });
            opt(&mut o, "Reason", m.reason, |r| format!("{} {r:?}", r as u8));
            opt(&mut o, "Mission Checksum", m.mission_checksum, |c| {
                c.to_string()
            });
        }
        Message::FromToNext(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            opt(&mut o, "Altitude Type", m.altitude_type, |t| {
                t.numbered().to_string()
            });
            opt(&mut o, "Speed Type", m.speed_type, |t| {
                t.numbered().to_string()
            });
            let f = &m.from;
            opt(&mut o, "From Latitude", f.latitude, angle);
            opt(&mut o, "From Longitude", f.longitude, angle);
            opt(&mut o, "From Altitude", f.altitude, alt);
            opt(&mut o, "From Time", f.time, ts);
            opt(&mut o, "From Waypoint Number", f.waypoint_number, |n| {
                n.to_string()
            });
            for (label, s) in [("To", &m.to), ("Next", &m.next)] {
                opt(&mut o, &format!("{label} Latitude"), s.latitude, angle);
                opt(&mut o, &format!("{label} Longitude"), s.longitude, angle);
                opt(&mut o, &format!("{label} Altitude"), s.altitude, alt);
                opt(&mut o, &format!("{label} Speed"), s.speed, speed);
                opt(&mut o, &format!("{label} Time"), s.time, ts);
                opt(
                    &mut o,
                    &format!("{label} Waypoint Number"),
                    s.waypoint_number,
                    |n| n.to_string(),
                );
            }
            opt(
                &mut o,
                "Loiter Configuration Report Validity",
                m.loiter_configuration_report_validity,
                |v| v.to_string(),
            );
        }
        Message::InertialStates(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            opt(&mut o, "Latitude", m.latitude, angle);
            opt(&mut o, "Longitude", m.longitude, angle);
            opt(&mut o, "Altitude", m.altitude, alt);
            opt(&mut o, "Altitude Type", m.altitude_type, |t| {
                t.numbered().to_string()
            });
            opt(&mut o, "U Speed", m.u_speed, velocity);
            opt(&mut o, "V Speed", m.v_speed, velocity);
            opt(&mut o, "W Speed", m.w_speed, velocity);
            for (name, value) in [
                ("U Accel", m.u_accel),
                ("V Accel", m.v_accel),
                ("W Accel", m.w_accel),
                ("Phi", m.phi),
                ("Theta", m.theta),
                ("Psi", m.psi),
                ("Phi Dot", m.phi_dot),
                ("Theta Dot", m.theta_dot),
                ("Psi Dot", m.psi_dot),
                ("Magnetic Variation", m.magnetic_variation),
            ] {
                opt(&mut o, name, value, |v| v.to_string());
            }
        }
        Message::AreaTransmissionCommand(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Area Transfer Mode", m.mode.numbered()));
            opt(&mut o, "Area Loop Count", m.loop_count, |v| v.to_string());
            opt(&mut o, "Area ID", m.area_id, |v| v.to_string());
            opt(&mut o, "Safety Offset", m.safety_offset, offset);
            opt(&mut o, "Activity ID", m.activity_id, |a| {
                a.get().to_string()
            });
            opt(&mut o, "Mission ID", m.mission_id.as_ref(), text);
            opt(
                &mut o,
                "Transfer Window or Area Checksum",
                m.window_or_checksum,
                |w| match w {
                    WindowOrChecksum::TransferWindow(w) => format!("transfer window {w}"),
                    WindowOrChecksum::AreaChecksum(c) => format!("area checksum {c}"),
                },
            );
        }
        Message::AreaPolygonLoopSegment(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Area ID", m.area_id));
            o.push(kv("Area Type", m.area_type.numbered()));
            let points: Vec<GeoPoint> = match &m.shape {
                AreaShape::Polygon(v) => v.iter().copied().collect(),
                AreaShape::Circle { centre, border } => vec![*centre, *border],
            };
            o.push(kv(
                "Activity ID",
                match m.shape {
                    AreaShape::Polygon(_) => "0 (polygon)",
                    AreaShape::Circle { .. } => "1 (circle)",
                },
            ));
            opt(&mut o, "Lower Altitude", m.lower_altitude, alt);
            opt(&mut o, "Upper Altitude", m.upper_altitude, alt);
            opt(&mut o, "Altitude Type", m.altitude_type, |t| {
                t.numbered().to_string()
            });
            o.push(kv("Vertex Count", points.len()));
            let list: Vec<String> = points.iter().map(point).collect();
            o.push(kv("Vertices", format!("{} (deg)", list.join("; "))));
        }
        Message::AreaStatusAlert(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Area Loop Count", m.loop_count));
            o.push(kv("Status", m.status.numbered()));
            opt(&mut o, "Reason", m.reason, |r| format!("{} {r:?}", r as u8));
        }
        Message::AreaTransmissionStatus(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Area ID", m.area_id));
            o.push(kv("Area Loop Count", m.loop_count));
            o.push(kv("Safety Offset", offset(m.safety_offset)));
            o.push(kv("Status", m.status.numbered()));
        }
        Message::MissionExecuteCommand(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Command", m.command.numbered()));
            opt(&mut o, "Mission ID", m.mission_id.as_ref(), text);
        }
        Message::MissionReport(m) => {
            o.push(kv("Time Stamp", ts(m.time_stamp)));
            o.push(kv("Report Index", m.report_index));
            o.push(kv("Report Count", m.report_count));
            opt(&mut o, "Mission ID", m.mission_id.as_ref(), text);
            o.push(kv("Waypoint Count", m.waypoint_count));
            o.push(kv("Area Count", m.area_count));
            o.push(kv("Geofence Check", m.geofence_check.numbered()));
            opt(&mut o, "Reason", m.reason, |r| format!("{} {r:?}", r as u8));
            opt(&mut o, "Mission Checksum", m.mission_checksum, |c| {
                c.to_string()
            });
            opt(&mut o, "Area Checksum", m.area_checksum, |c| c.to_string());
        }
    }
    o
}
