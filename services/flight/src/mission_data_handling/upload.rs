//! Uploads to the FCC (ICD §5.1, §5.3): the waypoint buffer and the area buffer, their closers
//! (answered once and remembered, ICD §11), the clears, and a restart's interrupted upload.

use super::*;

impl MissionDataHandling {
    /// Whether a mission upload is open, cut by a restart included.
    pub(super) fn mission_upload_open(&self) -> bool {
        self.mission_upload.in_transfer() || self.interrupted_until.is_some()
    }

    /// Tells the driver when a mission upload opened or closed, to record it before the answers
    /// go out.
    pub(super) fn record_upload_state(&mut self) {
        let open = self.mission_upload_open();
        if open != self.upload_recorded_open {
            self.upload_recorded_open = open;
            self.event(if open {
                FccEvent::MissionUploadOpened
            } else {
                FccEvent::MissionUploadClosed
            });
        }
    }

    /// The mission upload cut by a restart heard from the GCS again: refused (it cannot be
    /// resumed), and held for another transfer timeout.
    pub(super) fn refuse_interrupted(&mut self, now: Instant) -> Result<(), Reason> {
        self.interrupted_until = Some(now + self.config.transfer_timeout);
        Err(Reason::WrongState)
    }

    /// Answers `message` (an opener or a data message of a transfer) with `outcome`; an
    /// accepted one ends the memory of the last closer of its kind (ICD §11): an area opener
    /// sent beside the mission upload leaves the mission closer's (ICD §10.3).
    pub(super) fn answer_transfer(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        outcome: Result<(), Reason>,
    ) {
        if outcome.is_ok() {
            self.closers.accepted(message);
        }
        self.endpoint.answer(now, message, ack, outcome);
    }

    /// A closer (ICD §10.2): the retry of the closer answered last gets the same answer and
    /// changes nothing (ICD §11); any other is carried out and remembered.
    pub(super) fn closer(&mut self, now: Instant, message: &Message, ack: bool) {
        let answer = match Closer::of(message) {
            Some(closer) => match self.closers.repeat(&closer) {
                Some(answer) => answer,
                None => {
                    let answer = self.close(now, message);
                    self.closers.remember(closer, answer);
                    answer
                }
            },
            None => self.close(now, message),
        };
        self.answer_closer(now, message, ack, answer);
    }

    /// Carries out a closer: assembles the list and activates it (mode 2) or stages it (ICD §8:
    /// #13000 mode 8, #2011 mode 7), or says why not.
    pub(super) fn close(&mut self, now: Instant, message: &Message) -> ClosingAnswer {
        match message {
            Message::AreaTransmissionCommand(_) => self.complete_area_upload(now, message),
            Message::MissionTransferCommand(c) if c.mode == MissionPlanMode::StageMission => {
                ClosingAnswer::Acknowledgement(self.stage_mission(now, message, c.mission_id))
            }
            _ => ClosingAnswer::Acknowledgement(self.mission_data(now, message)),
        }
    }

    /// Sends `answer` to the closer `message`: #17000 or #3012.
    pub(super) fn answer_closer(
        &mut self,
        now: Instant,
        message: &Message,
        ack: bool,
        answer: ClosingAnswer,
    ) {
        match answer {
            ClosingAnswer::Acknowledgement(outcome) => {
                self.endpoint.answer(now, message, ack, outcome);
            }
            ClosingAnswer::AreaStatus {
                loop_count,
                outcome,
            } => {
                let alert = AreaStatusAlert {
                    time_stamp: Timestamp::default(),
                    loop_count,
                    status: if outcome.is_ok() {
                        AreaListStatus::Valid
                    } else {
                        AreaListStatus::Invalid
                    },
                    reason: Some(outcome.err().unwrap_or(Reason::None)),
                };
                self.endpoint.send(now, alert.into(), false);
            }
        }
    }

    /// #13000 mode 1 stamped `stamp` (ICD §5.1 step 1). Overtaken on the link by the data
    /// sent behind it, it leaves what they stored (ICD §10.3); one stamped before an opener this
    /// upload applied is late and changes nothing (`WrongState`).
    pub(super) fn clear_mission(&mut self, now: Instant, stamp: Timestamp) -> Result<(), Reason> {
        if self.automation.trajectory_generation_active {
            return Err(Reason::GuidanceActive);
        }
        if self.mission_download.is_some() {
            return Err(Reason::Busy);
        }
        // Paper §3.1: the clear deletes the waypoint buffer and the waypoint list (ICD §5.1
        // step 1); guidance sees the empty list as one activation.
        self.mission_upload.clear(now, stamp)?;
        if self.active_mission.is_some() {
            self.activate(Activation::Mission(None));
            self.closers.forget();
        }
        Ok(())
    }

    pub(super) fn clear_areas(&mut self) -> Result<(), Reason> {
        if self.automation.trajectory_generation_active {
            return Err(Reason::GuidanceActive);
        }
        if self.area_download.is_some() || self.area_upload.in_transfer() {
            return Err(Reason::Busy);
        }
        if self.active_areas.is_some() {
            self.activate(Activation::Areas(None));
            self.closers.forget();
        }
        Ok(())
    }

    /// One message of a mission upload to the waypoint buffer: a data message or a closer
    /// (#13000 mode 2 or 8), handed to the receiver.
    pub(super) fn upload_step(
        &mut self,
        now: Instant,
        message: &Message,
    ) -> Result<Received, Reason> {
        if self.mission_download.is_some() {
            return Err(Reason::WrongState);
        }
        if self.interrupted_until.is_some() {
            self.refuse_interrupted(now)?;
        }
        if !self.mission_upload.in_transfer() {
            // An upload without clear (or mode 10) edits the active mission, as in edition 1.
            self.mission_upload.abandon(self.active_mission.as_ref());
        }
        self.mission_upload.handle(now, message)
    }

    /// Mission upload: store, or assemble and activate on #13000 mode 2.
    pub(super) fn mission_data(&mut self, now: Instant, message: &Message) -> Result<(), Reason> {
        match self.upload_step(now, message)? {
            Received::Complete => {
                let Some(mission) = self.mission_upload.take() else {
                    return Err(Reason::WrongState);
                };
                if self.active_mission.as_ref() != Some(&mission) {
                    self.activate(Activation::Mission(Some(mission)));
                }
                Ok(())
            }
            Received::Emptied => {
                if self.active_mission.is_some() {
                    self.activate(Activation::Mission(None));
                }
                Ok(())
            }
            Received::Stored | Received::Abandoned(_) => Ok(()),
        }
    }

    /// #2011 mode 2 or 7 (ICD §5.3, §8): assembles the area list, then activates it or stores it
    /// under the Mission ID; answered by #3012 with the loop count of that list.
    pub(super) fn complete_area_upload(
        &mut self,
        now: Instant,
        message: &Message,
    ) -> ClosingAnswer {
        let result = self.area_closer(now, message);
        ClosingAnswer::AreaStatus {
            loop_count: result.unwrap_or(0),
            outcome: result.map(|_| ()),
        }
    }

    /// The area closer `message`: the loop count of the list activated or staged, or why not.
    pub(super) fn area_closer(&mut self, now: Instant, message: &Message) -> Result<u8, Reason> {
        let staged = match message {
            Message::AreaTransmissionCommand(c)
                if c.mode == AreaTransferMode::UploadCompleteStaged =>
            {
                Some(staged_id(c.mission_id)?)
            }
            _ => None,
        };
        if self.area_download.is_some() {
            return Err(Reason::WrongState);
        }
        if staged.is_some_and(|id| !self.staged.can_store(&id)) {
            return Err(Reason::Capacity);
        }
        match self.area_upload.handle(now, message)? {
            Received::Complete => {}
            Received::Stored | Received::Abandoned(_) | Received::Emptied => {
                return Err(Reason::WrongState);
            }
        }
        let list = self.area_upload.take().ok_or(Reason::WrongState)?;
        let loop_count = list.areas.len() as u8;
        match staged {
            Some(id) => {
                if self.staged.store_areas(id, list)? {
                    self.event(FccEvent::StagedStored {
                        id,
                        kind: DataKind::Areas,
                    });
                }
            }
            None => {
                if self.active_areas.as_ref() != Some(&list) {
                    self.activate(Activation::Areas(Some(list)));
                }
            }
        }
        Ok(loop_count)
    }

    pub(super) fn upload_timed_out(&mut self, kind: DataKind, timed_out: TransferTimedOut) {
        tracing::warn!(
            ?kind,
            last_heard = ?timed_out.last_heard,
            "upload abandoned: nothing heard for the transfer timeout"
        );
        self.event(FccEvent::UploadAbandoned { kind, reason: None });
    }
}
