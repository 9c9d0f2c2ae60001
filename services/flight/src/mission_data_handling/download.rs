//! Downloads from the FCC (ICD §5.2, §5.4, §8) and the report (#50001): who sends what, a newer
//! opener that ends what is left open, and cancels.

use super::*;

impl MissionDataHandling {
    /// #13000 mode 3 (the active mission, ICD §5.2) or mode 9 (a staged mission's, ICD §8):
    /// acknowledged, then the download. No such list: `WrongState`, nothing follows.
    /// Ends the transfers of `kind` still open when `opener`, a transfer's opener from the GCS,
    /// is stamped after them: a download stamped-after its request, an upload after its newest
    /// message.
    ///
    /// The GCS runs one transfer at a time (ICD §5) and opens the next only when it is done
    /// with the one before, so such a transfer has no peer left. Kept, it would refuse the
    /// GCS's new transfer `Busy`:
    /// - a download, for up to twice the ack timeout, while it waits for the answer to its last
    ///   message that the GCS sent and the link lost (the `bad` link of `src/link_emulator.rs`);
    /// - an upload, for the transfer timeout, when a data message resent before the GCS gave
    ///   up arrives late, after the cancel, and opens an edit of its own (ICD §5.1: an upload
    ///   without clear edits the active mission).
    ///
    /// Ending an upload abandons its buffer; the active lists never change by it (§7). An
    /// opener stamped before is an old one, delayed on the link: it meets the transfer as
    /// before. This project's choice: the ICD says nothing of transfers that outlive their GCS.
    pub(super) fn end_transfers_before(&mut self, kind: DataKind, opener: &Message) {
        let stamp = opener.time_stamp();
        let (requested, uploaded, download) = match kind {
            DataKind::Mission => (
                self.download_requests[0],
                self.upload_stamps[0],
                &mut self.mission_download,
            ),
            DataKind::Areas => (
                self.download_requests[1],
                self.upload_stamps[1],
                &mut self.area_download,
            ),
            DataKind::Report => return,
        };
        if stamp > requested {
            if let Some(mut d) = download.take() {
                d.cancel();
                self.event(FccEvent::DownloadEnded { kind });
            }
        }
        if stamp <= uploaded {
            return;
        }
        let abandoned = match kind {
            DataKind::Mission if self.mission_upload.in_transfer() => {
                self.mission_upload.abandon(self.active_mission.as_ref());
                true
            }
            DataKind::Areas if self.area_upload.in_transfer() => {
                self.area_upload.abandon();
                true
            }
            _ => false,
        };
        if abandoned {
            self.event(FccEvent::UploadAbandoned { kind, reason: None });
        }
    }

    pub(super) fn start_mission_download(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        request: &MissionTransferCommand,
    ) {
        let mission = if request.mode == MissionPlanMode::ReceiveStagedMission {
            staged_id(request.mission_id)
                .map(|id| self.staged.get(&id).and_then(|e| e.mission.clone()))
        } else {
            Ok(self.active_mission.clone())
        };
        let busy = self.mission_download.is_some() || self.mission_upload.in_transfer();
        let mission = match mission {
            Err(reason) => Err(reason),
            Ok(_) if busy => Err(Reason::Busy),
            Ok(None) => Err(Reason::WrongState),
            Ok(Some(mission)) => Ok(mission),
        };
        self.answer_transfer(
            now,
            message,
            ack,
            mission.as_ref().map(|_| ()).map_err(|r| *r),
        );
        if let Ok(mission) = mission {
            // Edition-2 fields only to an edition-2 request (ICD §10.2: it carries the window).
            let checksum = request
                .transfer_window
                .is_some()
                .then(|| mission_checksum(&mission));
            // ICD §10.2: the window the GCS put into its request, 1 when absent.
            let window = request.transfer_window.unwrap_or_default().get();
            self.download_requests[0] = message.time_stamp();
            self.mission_download = Some(TransferSender::start_windowed(
                Script::MissionDownload { mission, checksum },
                usize::from(window),
                self.config.ack_timeout,
                &mut self.endpoint,
                now,
            ));
        }
    }

    /// #2011 mode 3 (the active areas, ICD §5.4) or mode 8 (a staged mission's, ICD §8): opened
    /// by #3013. With mode 8, an invalid Mission ID or no such list is answered by #17000 type 3
    /// (`Malformed`, `WrongState`) and nothing follows (ICD §8); busy is answered as for mode 3.
    pub(super) fn start_area_download(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        request: &AreaTransmissionCommand,
    ) {
        let list = if request.mode == AreaTransferMode::InitiateStagedDownload {
            let list = staged_id(request.mission_id).and_then(|id| {
                self.staged
                    .get(&id)
                    .and_then(|e| e.areas.clone())
                    .ok_or(Reason::WrongState)
            });
            match list {
                Ok(list) => Some(list),
                Err(reason) => {
                    self.endpoint.answer(now, message, ack, Err(reason));
                    return;
                }
            }
        } else {
            self.active_areas.clone()
        };
        // ICD §4 #2011 field 3: "mode 3: 0 = all areas, else that one" (mode 8 "as with mode
        // 3"). An Area ID the list does not hold leaves nothing to send: aborted, as an empty
        // list is.
        let area_id = request.area_id.unwrap_or(0);
        let list = match area_id {
            0 => list,
            id => list.and_then(|l| l.only(id)),
        };
        let busy = self.area_download.is_some() || self.area_upload.in_transfer();
        match (list, busy) {
            (Some(list), false) => {
                // An opener of an area transfer (ICD §11: the area closer's memory ends).
                self.closers.accepted(message);
                // Edition-2 fields only to an edition-2 request (ICD §10.2).
                let checksum = request
                    .transfer_window()
                    .is_some()
                    .then(|| areas_checksum(&list));
                let window = request.transfer_window().unwrap_or_default().get();
                self.download_requests[1] = message.time_stamp();
                self.area_download = Some(TransferSender::start_windowed(
                    Script::AreaDownload {
                        list,
                        area_id,
                        checksum,
                    },
                    usize::from(window),
                    self.config.ack_timeout,
                    &mut self.endpoint,
                    now,
                ));
            }
            // Nothing to send, or busy: the #3013 says aborted (ICD §4: status 2).
            _ => {
                let status = AreaTransmissionStatus {
                    time_stamp: Timestamp::default(),
                    area_id,
                    loop_count: 0,
                    safety_offset: SafetyOffset::default(),
                    status: AreaDownloadStatus::Aborted,
                };
                self.endpoint.send(now, status.into(), false);
            }
        }
    }

    /// The sender of the download (or the report) of `kind`, and the endpoint it sends on.
    pub(super) fn outgoing(
        &mut self,
        kind: DataKind,
    ) -> (&mut Option<TransferSender>, &mut Endpoint) {
        let slot = match kind {
            DataKind::Mission => &mut self.mission_download,
            DataKind::Areas => &mut self.area_download,
            DataKind::Report => &mut self.report,
        };
        (slot, &mut self.endpoint)
    }

    /// #13000 mode 7 (ICD §8): acknowledged, then the report of the active lists (and, with
    /// staged missions, of each). A new request replaces a report still in progress: the GCS
    /// that asks again has given up the earlier one.
    pub(super) fn start_report(&mut self, now: Instant, message: &Message, ack: bool) {
        self.endpoint.answer(now, message, ack, Ok(()));
        if let Some(mut old) = self.report.take() {
            old.cancel();
        }
        let (geofence_check, reason) = automation::report_check(
            self.waypoint_list.is_active().then(|| {
                missionlink_protocol::geofence::flown_route::RouteView::from(&self.waypoint_list)
            }),
            (self.area_list.area_count() > 0).then_some(&*self.fence),
            &self.navigation,
        );
        let count = (1 + self.staged.len()) as u8;
        let active = MissionReport {
            time_stamp: Timestamp::default(),
            report_index: 1,
            report_count: count,
            // Present and empty: the active lists (ICD §8).
            mission_id: Some(Text::default()),
            waypoint_count: self
                .active_mission
                .as_ref()
                .map_or(0, |m| m.waypoints.len() as u16),
            area_count: self
                .active_areas
                .as_ref()
                .map_or(0, |a| a.areas.len() as u8),
            geofence_check,
            reason,
            mission_checksum: self.active_mission.as_ref().map(mission_checksum),
            area_checksum: self.active_areas.as_ref().map(areas_checksum),
        };
        let mut entries = heapless::Vec::new();
        // At most MAX_REPORT_ENTRIES: the active lists and MAX_STAGED_MISSIONS.
        let _ = entries.push(active);
        // Then each staged mission in ascending byte order of its ID (ICD §8), with the check
        // execute would run after its activation, against a fence built for its areas.
        for (index, entry) in self.staged.iter().enumerate() {
            let fence = entry.areas.as_ref().map(|a| {
                self.staged_fence.set_list(a);
                &*self.staged_fence
            });
            let (geofence_check, reason) = automation::report_check(
                entry
                    .mission
                    .as_ref()
                    .map(missionlink_protocol::geofence::flown_route::RouteView::from),
                fence,
                &self.navigation,
            );
            let _ = entries.push(MissionReport {
                time_stamp: Timestamp::default(),
                report_index: (index + 2) as u8,
                report_count: count,
                mission_id: Some(entry.id.text()),
                waypoint_count: entry
                    .mission
                    .as_ref()
                    .map_or(0, |m| m.waypoints.len() as u16),
                area_count: entry.areas.as_ref().map_or(0, |a| a.areas.len() as u8),
                geofence_check,
                reason,
                mission_checksum: entry.mission.as_ref().map(mission_checksum),
                area_checksum: entry.areas.as_ref().map(areas_checksum),
            });
        }
        self.report = Some(TransferSender::start(
            Script::MissionReport { entries },
            self.config.ack_timeout,
            &mut self.endpoint,
            now,
        ));
    }

    pub(super) fn download_answer(&mut self, now: Instant, message: &Message) {
        for kind in [DataKind::Mission, DataKind::Areas, DataKind::Report] {
            let (slot, endpoint) = self.outgoing(kind);
            let Some(sender) = slot.as_mut() else {
                continue;
            };
            if let Some(event) = sender.handle_answer(endpoint, now, message) {
                self.download_event(kind, event);
                return;
            }
        }
        tracing::debug!("acknowledgement that answers nothing outstanding");
    }

    pub(super) fn download_event(&mut self, kind: DataKind, event: SenderEvent) {
        let (slot, _) = self.outgoing(kind);
        match event {
            SenderEvent::Progress { .. } => {}
            SenderEvent::Completed(_) => {
                *slot = None;
                self.event(FccEvent::DownloadComplete { kind });
            }
            SenderEvent::Failed(error) => {
                *slot = None;
                self.event(FccEvent::DownloadFailed { kind, error });
            }
        }
    }

    pub(super) fn cancel(&mut self, kind: DataKind) {
        match kind {
            DataKind::Mission => {
                if let Some(mut d) = self.mission_download.take() {
                    d.cancel();
                }
                if self.mission_upload.in_transfer() {
                    self.mission_upload.abandon(self.active_mission.as_ref());
                    self.event(FccEvent::UploadAbandoned { kind, reason: None });
                }
                self.interrupted_until = None;
            }

            DataKind::Areas => {
                if let Some(mut d) = self.area_download.take() {
                    d.cancel();
                }
                if self.area_upload.in_transfer() {
                    self.area_upload.abandon();
                    self.event(FccEvent::UploadAbandoned { kind, reason: None });
                }
            }
            DataKind::Report => {
                if let Some(mut r) = self.report.take() {
                    r.cancel();
                }
            }
        }
    }
}
