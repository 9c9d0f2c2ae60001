//! The enumerations of ICD §4, one per field that has named values. An undefined value decodes to
//! [`Cause::Unsupported`](super::error::Cause::Unsupported) ("a value this system does not
//! implement").

wire_enum! {
    /// #17000 field 3, Acknowledgement Type.
    pub enum AckType {
        /// Received.
        Received = 0,
        /// Partially received.
        PartiallyReceived = 1,
        /// Completed (success).
        Completed = 2,
        /// Rejected (failure), with a reason.
        Rejected = 3,
        /// Receive failed.
        ReceiveFailed = 4,
    }
}

wire_enum! {
    /// #13000 field 2, Mission Plan Mode (and #14000 field 5). Mode 4 of STANAG is not
    /// implemented here.
    pub enum MissionPlanMode {
        /// Clear the waypoint buffer and the active list.
        ClearMission = 1,
        /// Assemble the waypoint list from the buffer, validate and activate it.
        TransmitMission = 2,
        /// Download the active mission to the GCS.
        ReceiveMission = 3,
        /// Cancel the transfer in progress.
        CancelTransfer = 5,
    }
}

wire_enum! {
    /// #13001 field 3, Route Type.
    pub enum RouteType {
        /// Launch.
        Launch = 0,
        /// Approach.
        Approach = 1,
        /// Flight.
        Flight = 2,
        /// Contingency A.
        ContingencyA = 3,
        /// Contingency B.
        ContingencyB = 4,
    }
}

wire_enum! {
    /// #13002 field 4, Location Type. Relative locations (1) are `Unsupported`.
    pub enum LocationType {
        /// Absolute latitude and longitude.
        Absolute = 0,
    }
}

wire_enum! {
    /// Altitude Type of #13002, #2012 and #4001.
    pub enum AltitudeType {
        /// Pressure altitude.
        Pressure = 0,
        /// Barometric altitude.
        Baro = 1,
        /// Above ground level.
        Agl = 2,
        /// Height above the WGS-84 ellipsoid.
        Wgs84 = 3,
    }
}

wire_enum! {
    /// Speed Type of #13002 and #4001.
    pub enum SpeedType {
        /// Indicated airspeed.
        IndicatedAirspeed = 0,
        /// True airspeed.
        TrueAirspeed = 1,
        /// Ground speed.
        GroundSpeed = 2,
    }
}

wire_enum! {
    /// #13002 field 11, Turn Type.
    pub enum TurnType {
        /// Fly-by: turn short of the waypoint.
        FlyBy = 0,
        /// Fly-over: pass over the waypoint, then turn.
        FlyOver = 1,
    }
}

wire_enum! {
    /// #13002 field 13, Waypoint Type: the ARINC 424 leg type of the leg that ends at the
    /// waypoint.
    pub enum LegType {
        /// Track-to-fix: a geodesic line (WGS-84).
        TrackToFix = 0,
        /// Radius-to-fix: an arc around a centre given by #13006 type 2.
        RadiusToFix = 1,
    }
}

wire_enum! {
    /// #13006 field 6, Turn Direction of a radius-to-fix leg.
    pub enum TurnDirection {
        /// Clockwise (right turn).
        Clockwise = 0,
        /// Counter-clockwise (left turn).
        CounterClockwise = 1,
    }
}

wire_enum! {
    /// #14000 field 2, Status of a mission upload or download.
    pub enum TransferStatus {
        /// In progress.
        InProgress = 0,
        /// Complete.
        Complete = 1,
        /// Aborted, with a reason.
        Aborted = 2,
    }
}

wire_enum! {
    /// #2011 field 1, Area Transfer Mode.
    pub enum AreaTransferMode {
        /// Initiate upload: Area Loop Count areas follow.
        InitiateUpload = 1,
        /// Upload complete: assemble and validate the area list.
        UploadComplete = 2,
        /// Initiate download.
        InitiateDownload = 3,
        /// Download complete.
        DownloadComplete = 4,
        /// Cancel the transfer in progress.
        Cancel = 5,
        /// Clear the areas.
        ClearAreas = 6,
    }
}

wire_enum! {
    /// #2012 field 2, Area Type.
    pub enum AreaType {
        /// Stay-in: the fly-zone (FZ).
        FlyZone = 0,
        /// Keep-out: a no-fly-zone (NFZ).
        NoFlyZone = 1,
    }
}

wire_enum! {
    /// #3012 field 2, Status of the assembled area list.
    pub enum AreaListStatus {
        /// Area list invalid (upload failed), with a reason.
        Invalid = 0,
        /// Area list valid and active (upload succeeded).
        Valid = 1,
    }
}

wire_enum! {
    /// #3013 field 4, Status of an area download.
    pub enum AreaDownloadStatus {
        /// Ready: the areas follow.
        Ready = 0,
        /// Aborted.
        Aborted = 2,
    }
}

wire_enum! {
    /// #50000 field 1, Command.
    pub enum ExecuteCommand {
        /// Take off and fly the active mission.
        Execute = 1,
        /// Fly the route backwards to its start (bidirectional routes only).
        ReturnToHome = 2,
        /// Land at the next waypoint.
        Land = 3,
    }
}
