//! The geoid: where mean sea level lies against the WGS-84 ellipsoid, the one vertical datum the
//! ground side converts with. The ICD's altitudes are WGS-84 heights (ICD §3, altitude type 3);
//! MAVLink's AMSL altitudes (GLOBAL_POSITION_INT `alt`, HOME_POSITION) and QGroundControl's
//! global frames (0, 5) are heights above mean sea level. Between the two lies the geoid
//! undulation N, 45.5 m at the demo's airfield: an AMSL altitude taken as WGS-84 would put
//! the aircraft 45 m lower than the operator planned.
//!
//! The model is EGM96 (the `egm96` crate: NGA's spherical harmonics to degree 360), which GNSS
//! receivers and autopilots report MSL altitudes against. An evaluation costs about a millisecond,
//! so the value is kept per cell of 1/120 degree (at most 930 m across), for the whole process:
//! the undulation's gradient, at most a few centimetres per kilometre outside the steepest
//! mountain ranges, moves it by less than the wire's altitude step within a cell, and the ground
//! service's vehicles (their positions, every upload's take-off position) share their cells. An
//! evaluation also takes over half a megabyte of stack, which a thread keeps resident once it
//! has touched it: it runs on a short-lived thread of its own, so that the ground service's
//! threads stay small.

use std::collections::HashMap;
use std::sync::Mutex;

/// Cells per degree of the memo.
const CELLS_PER_DEGREE: f64 = 120.0;

/// The stack of an evaluation's thread: the model's 520 KB frame and room to spare.
const EVALUATION_STACK: usize = 2 << 20;

/// The most cells the memo keeps; past it, it starts again empty (a fleet spread over more than
/// 4096 cells of a kilometre re-evaluates some, and the memo stays some 100 KB).
const MEMO_CELLS: usize = 4096;

/// The cells evaluated and their undulations.
static MEMO: Mutex<Option<HashMap<(i64, i64), f64>>> = Mutex::new(None);

/// The geoid undulation N at a position, metres: the height of mean sea level above the WGS-84
/// ellipsoid (positive where the geoid lies above it).
pub fn undulation_m(latitude_deg: f64, longitude_deg: f64) -> f64 {
    let cell = (
        (latitude_deg * CELLS_PER_DEGREE).round() as i64,
        (longitude_deg * CELLS_PER_DEGREE).round() as i64,
    );
    let known = |memo: &Option<HashMap<(i64, i64), f64>>| memo.as_ref()?.get(&cell).copied();
    if let Some(n) = MEMO.lock().ok().and_then(|memo| known(&memo)) {
        return n;
    }
    let (lat, lon) = (
        cell.0 as f64 / CELLS_PER_DEGREE,
        cell.1 as f64 / CELLS_PER_DEGREE,
    );
    let evaluate = move || egm96::egm96_compute_altitude_offset(lat, lon);
    // Where no thread can be started, on this one.
    let n = std::thread::Builder::new()
        .name("geoid".to_owned())
        .stack_size(EVALUATION_STACK)
        .spawn(evaluate)
        .ok()
        .and_then(|t| t.join().ok())
        .unwrap_or_else(evaluate);
    if let Ok(mut memo) = MEMO.lock() {
        let memo = memo.get_or_insert_with(HashMap::new);
        if memo.len() >= MEMO_CELLS {
            memo.clear();
        }
        memo.insert(cell, n);
    }
    n
}

/// The height above mean sea level of a WGS-84 height at a position.
pub fn amsl_from_wgs84(wgs84_m: f64, latitude_deg: f64, longitude_deg: f64) -> f64 {
    wgs84_m - undulation_m(latitude_deg, longitude_deg)
}

/// The WGS-84 height of a height above mean sea level at a position.
pub fn wgs84_from_amsl(amsl_m: f64, latitude_deg: f64, longitude_deg: f64) -> f64 {
    amsl_m + undulation_m(latitude_deg, longitude_deg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Published EGM96 undulations: 45.48 m near Munich (the PyPI `egm96` package's example,
    /// from GeographicLib's 5' grid) and 17.16 m at (0, 0) (NGA's EGM96 calculator).
    #[test]
    fn undulation_where_it_is_known() {
        for (lat, lon, n) in [(48.14, 11.58, 45.48), (0.0, 0.0, 17.16)] {
            let got = undulation_m(lat, lon);
            assert!(
                (got - n).abs() < 0.05,
                "N at ({lat}, {lon}): {got} m, expected {n} m"
            );
        }
    }

    #[test]
    fn amsl_and_wgs84_are_inverse() {
        let h = 567.25;
        let amsl = amsl_from_wgs84(h, 48.26, 11.66);
        assert!((amsl - (h - undulation_m(48.26, 11.66))).abs() < 1e-9);
        assert!((wgs84_from_amsl(amsl, 48.26, 11.66) - h).abs() < 1e-9);
    }
}
