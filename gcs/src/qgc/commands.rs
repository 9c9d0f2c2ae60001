//! The names of the MAVLink commands and frames a `.plan` uses, for the messages of the import.

pub(super) fn command_name(command: u64) -> &'static str {
    match command {
        16 => "NAV_WAYPOINT",
        17 => "NAV_LOITER_UNLIM",
        18 => "NAV_LOITER_TURNS",
        19 => "NAV_LOITER_TIME",
        20 => "NAV_RETURN_TO_LAUNCH",
        21 => "NAV_LAND",
        22 => "NAV_TAKEOFF",
        30 => "NAV_CONTINUE_AND_CHANGE_ALT",
        31 => "NAV_LOITER_TO_ALT",
        82 => "NAV_SPLINE_WAYPOINT",
        84 => "NAV_VTOL_TAKEOFF",
        85 => "NAV_VTOL_LAND",
        93 => "NAV_DELAY",
        112 => "CONDITION_DELAY",
        114 => "CONDITION_DISTANCE",
        115 => "CONDITION_YAW",
        177 => "DO_JUMP",
        178 => "DO_CHANGE_SPEED",
        179 => "DO_SET_HOME",
        183 => "DO_SET_SERVO",
        189 => "DO_LAND_START",
        195 => "DO_SET_ROI_LOCATION",
        197 => "DO_SET_ROI_NONE",
        201 => "DO_SET_ROI",
        203 => "DO_DIGICAM_CONTROL",
        205 => "DO_MOUNT_CONTROL",
        206 => "DO_SET_CAM_TRIGG_DIST",
        530 => "SET_CAMERA_MODE",
        2000 => "IMAGE_START_CAPTURE",
        2001 => "IMAGE_STOP_CAPTURE",
        2500 => "VIDEO_START_CAPTURE",
        2501 => "VIDEO_STOP_CAPTURE",
        3000 => "DO_VTOL_TRANSITION",
        _ => "unknown command",
    }
}

pub(super) fn frame_name(frame: u64) -> &'static str {
    match frame {
        0 => "GLOBAL",
        1 => "LOCAL_NED",
        2 => "MISSION",
        3 => "GLOBAL_RELATIVE_ALT",
        4 => "LOCAL_ENU",
        5 => "GLOBAL_INT",
        6 => "GLOBAL_RELATIVE_ALT_INT",
        7 => "LOCAL_OFFSET_NED",
        10 => "GLOBAL_TERRAIN_ALT",
        11 => "GLOBAL_TERRAIN_ALT_INT",
        _ => "unknown frame",
    }
}
