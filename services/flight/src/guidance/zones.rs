//! The fly-zone and no-fly-zone status of the position reported in the progress, on the
//! geofence of the area list, and the warnings logged on a change.

use missionlink_interfaces::contracts::AreaListPayload;

use super::Guidance;
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::zone::{Fence, Zone, ZoneKind};

/// The area list as the geofence holds it ([`Fence`]), built once when the list arrives so that
/// the zone test of each step allocates nothing.
#[derive(Debug, Clone, Default)]
pub(super) struct Areas {
    /// `None` without an area list. Boxed: a fence holds every border in fixed capacity.
    pub(super) fence: Option<Box<Fence>>,
}

impl Areas {
    pub(super) fn new(list: &AreaListPayload) -> Self {
        Self {
            fence: (list.generation != 0).then(|| Box::new(Fence::of_payload(list))),
        }
    }

    pub(super) fn zones(&self) -> impl Iterator<Item = &Zone> {
        self.fence.iter().flat_map(|f| f.zones.iter())
    }

    pub(super) fn inside_fly_zone(&self, at: &Site) -> bool {
        self.zones()
            .any(|z| z.kind == ZoneKind::FlyZone && z.contains(at))
    }

    /// Area ID of the first no-fly-zone (polygons, then circles: the fence's order) containing
    /// `at`, else 0.
    pub(super) fn no_fly_zone_at(&self, at: &Site) -> u16 {
        self.zones()
            .find(|z| z.kind == ZoneKind::NoFlyZone && z.contains(at))
            .map_or(0, |z| z.id)
    }
}

impl Guidance {
    /// Inside the fly-zone, and the no-fly-zone the aircraft is in (0: none), where it is now.
    pub(super) fn zone_status(&self) -> (bool, u16) {
        let at = Site::of(self.position);
        (
            self.areas.inside_fly_zone(&at),
            self.areas.no_fly_zone_at(&at),
        )
    }

    /// Updates the zone status and logs leaving the fly-zone and entering a no-fly-zone.
    pub(super) fn check_zones(&mut self) {
        let (inside, nfz) = self.zone_status();
        if self.inside_fly_zone && !inside {
            self.zone_warnings = self.zone_warnings.saturating_add(1);
            tracing::warn!(
                latitude_deg = self.position.y(),
                longitude_deg = self.position.x(),
                "left the fly-zone"
            );
        }
        if nfz != 0 && nfz != self.in_no_fly_zone {
            self.zone_warnings = self.zone_warnings.saturating_add(1);
            tracing::warn!(
                area_id = nfz,
                latitude_deg = self.position.y(),
                longitude_deg = self.position.x(),
                "entered a no-fly-zone"
            );
        }
        self.inside_fly_zone = inside;
        self.in_no_fly_zone = nfz;
    }
}
