//! The enumerations of ICD §4, one per field that has named values. An undefined value decodes to
//! [`Cause::Unsupported`](super::error::Cause::Unsupported) ("a value this system does not
//! implement").

wire_enum! {
    /// #17000 field 3, Acknowledgement Type.
    pub enum AckType {
        /// Received.
        Received = 0 => "received",
        /// Partially received.
        PartiallyReceived = 1 => "partially received",
        /// Completed (success).
        Completed = 2 => "completed",
        /// Rejected (failure), with a reason.
        Rejected = 3 => "rejected",
        /// Receive failed.
        ReceiveFailed = 4 => "receive failed",
    }
}

wire_enum! {
    /// #13000 field 2, Mission Plan Mode (and #14000 field 5). Mode 4 of STANAG is not
    /// implemented here.
    pub enum MissionPlanMode {
        /// Clear the waypoint buffer and the active list.
        ClearMission = 1 => "clear mission",
        /// Assemble the waypoint list from the buffer, validate and activate it.
        TransmitMission = 2 => "transmit mission",
        /// Download the active mission to the GCS.
        ReceiveMission = 3 => "receive mission",
        /// Cancel the transfer in progress.
        CancelTransfer = 5 => "cancel transfer",
        /// (ext, ICD §8) Delete the staged mission named by the Mission ID.
        DeleteStagedMission = 6 => "delete staged mission",
        /// (ext, ICD §8) Report the active lists and every staged mission (#50001); also how a
        /// GCS learns which edition the FCC speaks (ICD §10.1).
        ReportMissions = 7 => "report missions",
        /// (ext, ICD §8) Assemble and validate the waypoint list from the buffer and store it
        /// under the Mission ID; the active list does not change.
        StageMission = 8 => "stage mission",
        /// (ext, ICD §8) Download the staged mission named by the Mission ID.
        ReceiveStagedMission = 9 => "receive staged mission",
        /// (ext, ICD §8) Replace the waypoint buffer by the staged mission's waypoint list (or
        /// the active one, for an empty Mission ID) without touching any list.
        LoadWaypointBuffer = 10 => "load the waypoint buffer",
    }
}

wire_enum! {
    /// #13001 field 3, Route Type.
    pub enum RouteType {
        /// Launch.
        Launch = 0 => "launch",
        /// Approach.
        Approach = 1 => "approach",
        /// Flight.
        Flight = 2 => "flight",
        /// Contingency A.
        ContingencyA = 3 => "contingency A",
        /// Contingency B.
        ContingencyB = 4 => "contingency B",
    }
}

wire_enum! {
    /// #13002 field 4, Location Type. Relative locations (1) are `Unsupported`.
    pub enum LocationType {
        /// Absolute latitude and longitude.
        Absolute = 0 => "absolute",
    }
}

wire_enum! {
    /// Altitude Type of #13002, #2012 and #4001.
    pub enum AltitudeType {
        /// Pressure altitude.
        Pressure = 0 => "pressure",
        /// Barometric altitude.
        Baro = 1 => "baro",
        /// Above ground level.
        Agl = 2 => "AGL",
        /// Height above the WGS-84 ellipsoid.
        Wgs84 = 3 => "WGS-84",
    }
}

wire_enum! {
    /// Speed Type of #13002 and #4001.
    pub enum SpeedType {
        /// Indicated airspeed.
        IndicatedAirspeed = 0 => "indicated airspeed",
        /// True airspeed.
        TrueAirspeed = 1 => "true airspeed",
        /// Ground speed.
        GroundSpeed = 2 => "ground speed",
    }
}

wire_enum! {
    /// #13002 field 11, Turn Type.
    pub enum TurnType {
        /// Fly-by: turn short of the waypoint.
        FlyBy = 0 => "fly-by",
        /// Fly-over: pass over the waypoint, then turn.
        FlyOver = 1 => "fly-over",
    }
}

wire_enum! {
    /// #13002 field 13, Waypoint Type: the ARINC 424 leg type of the leg that ends at the
    /// waypoint.
    pub enum LegType {
        /// Track-to-fix: a geodesic line (WGS-84).
        TrackToFix = 0 => "track-to-fix",
        /// Radius-to-fix: an arc around a centre given by #13006 type 2.
        RadiusToFix = 1 => "radius-to-fix",
    }
}

wire_enum! {
    /// #13006 field 6, Turn Direction of a radius-to-fix leg.
    pub enum TurnDirection {
        /// Clockwise (right turn).
        Clockwise = 0 => "clockwise",
        /// Counter-clockwise (left turn).
        CounterClockwise = 1 => "counter-clockwise",
    }
}

wire_enum! {
    /// #14000 field 2, Status of a mission upload or download.
    pub enum TransferStatus {
        /// In progress.
        InProgress = 0 => "in progress",
        /// Complete.
        Complete = 1 => "complete",
        /// Aborted, with a reason.
        Aborted = 2 => "aborted",
    }
}

wire_enum! {
    /// #2011 field 1, Area Transfer Mode.
    pub enum AreaTransferMode {
        /// Initiate upload: Area Loop Count areas follow.
        InitiateUpload = 1 => "initiate upload",
        /// Upload complete: assemble and validate the area list.
        UploadComplete = 2 => "upload complete",
        /// Initiate download.
        InitiateDownload = 3 => "initiate download",
        /// Download complete.
        DownloadComplete = 4 => "download complete",
        /// Cancel the transfer in progress.
        Cancel = 5 => "cancel",
        /// Clear the areas.
        ClearAreas = 6 => "clear areas",
        /// (ext, ICD §8) Upload complete: assemble and validate the area list and store it
        /// under the Mission ID; the active list does not change.
        UploadCompleteStaged = 7 => "upload complete, stage under the Mission ID",
        /// (ext, ICD §8) Initiate download of the areas of the staged mission named by the
        /// Mission ID.
        InitiateStagedDownload = 8 => "initiate download of a staged mission's areas",
    }
}

wire_enum! {
    /// #2012 field 2, Area Type.
    pub enum AreaType {
        /// Stay-in: the fly-zone (FZ).
        FlyZone = 0 => "fly-zone",
        /// Keep-out: a no-fly-zone (NFZ).
        NoFlyZone = 1 => "no-fly-zone",
    }
}

wire_enum! {
    /// #3012 field 2, Status of the assembled area list.
    pub enum AreaListStatus {
        /// Area list invalid (upload failed), with a reason.
        Invalid = 0 => "invalid",
        /// Area list valid and active (upload succeeded).
        Valid = 1 => "valid",
    }
}

wire_enum! {
    /// #3013 field 4, Status of an area download.
    pub enum AreaDownloadStatus {
        /// Ready: the areas follow.
        Ready = 0 => "ready",
        /// Aborted.
        Aborted = 2 => "aborted",
    }
}

wire_enum! {
    /// #50000 field 1, Command.
    pub enum ExecuteCommand {
        /// Take off and fly the active mission.
        Execute = 1 => "execute",
        /// Fly the route backwards to its start (bidirectional routes only).
        ReturnToHome = 2 => "return to home",
        /// Land at the next waypoint.
        Land = 3 => "land",
        /// (ext, ICD §8) Make the staged mission named in field 2 the active waypoint and area
        /// lists, both in one step.
        ActivateStaged = 4 => "activate the staged mission",
    }
}

wire_enum! {
    /// #50001 field 6 (ext, ICD §8), Geofence Check: the onboard check of ICD §7 for one entry
    /// of a mission report.
    pub enum GeofenceCheck {
        /// Not run: the waypoint list or the area list is missing.
        NotRun = 0 => "not run",
        /// Passed.
        Passed = 1 => "passed",
        /// Failed, the reason in field 7.
        Failed = 2 => "failed",
    }
}
