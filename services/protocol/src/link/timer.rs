//! The timer table (after quinn-proto's `connection/timer.rs`): every deadline of a state machine
//! in one fixed array indexed by the machine's own `enum` of timers, so that "when must I be woken"
//! is [`TimerTable::next_timeout`] and "what is due" is [`TimerTable::expired`], instead of
//! deadlines kept in loose fields and combined by hand in each `poll_timeout`. The machines made
//! of transfers keep their tables in step with the transfers through
//! `crate::link::composite::Composite`.
//!
//! The state machines of ICD §5 have few timers (the ack timeout of a message in flight, the
//! transfer timeout of a receiver, one per transfer in a composite); the table holds them inline
//! and allocates nothing.

use core::fmt;
use core::marker::PhantomData;

use crate::link::time::Instant;

/// The timers of one state machine: an `enum` of `N` kinds, each a slot of its [`TimerTable`].
pub trait Timer<const N: usize>: Copy + Eq + fmt::Debug + 'static {
    /// Every timer, in [`Timer::index`] order; [`TimerTable::expired`] reports in this order.
    const ALL: [Self; N];

    /// The slot of this timer, below `N` (for a field-less enum: `self as usize`).
    fn index(self) -> usize;
}

/// Declares a timer `enum` and its [`Timer`] implementation from one list of variants, so the
/// slots, [`Timer::ALL`] and the variants cannot disagree: each variant's slot is its position.
///
/// ```
/// missionlink_protocol::timers! {
///     /// The timers of a transfer.
///     pub enum TransferTimer {
///         /// The ack timeout of the message in flight.
///         Ack,
///         /// The transfer timeout.
///         Transfer,
///     }
/// }
/// # use missionlink_protocol::link::timer::Timer;
/// assert_eq!(TransferTimer::ALL, [TransferTimer::Ack, TransferTimer::Transfer]);
/// assert_eq!(TransferTimer::Transfer.index(), 1);
/// ```
#[macro_export]
macro_rules! timers {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $( $(#[$variant_meta:meta])* $variant:ident ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $name {
            $( $(#[$variant_meta])* $variant ),+
        }

        impl $crate::link::timer::Timer<{ [$(stringify!($variant)),+].len() }> for $name {
            const ALL: [Self; [$(stringify!($variant)),+].len()] = [$(Self::$variant),+];

            fn index(self) -> usize {
                self as usize
            }
        }
    };
}

/// When each timer of `T` fires, if it is set.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct TimerTable<T: Timer<N>, const N: usize> {
    at: [Option<Instant>; N],
    timers: PhantomData<T>,
}

impl<T: Timer<N>, const N: usize> TimerTable<T, N> {
    /// A table with every timer stopped.
    pub const fn new() -> Self {
        Self {
            at: [None; N],
            timers: PhantomData,
        }
    }

    /// Sets `timer` to fire at `at` (a set timer is moved).
    pub fn set(&mut self, timer: T, at: Instant) {
        if let Some(slot) = self.at.get_mut(timer.index()) {
            *slot = Some(at);
        }
    }

    /// Sets `timer` to `at`, or stops it when `at` is `None`.
    pub fn set_or_stop(&mut self, timer: T, at: Option<Instant>) {
        if let Some(slot) = self.at.get_mut(timer.index()) {
            *slot = at;
        }
    }

    /// Stops `timer`.
    pub fn stop(&mut self, timer: T) {
        self.set_or_stop(timer, None);
    }

    /// When `timer` fires, if it is set.
    pub fn get(&self, timer: T) -> Option<Instant> {
        self.at.get(timer.index()).copied().flatten()
    }

    /// The earliest deadline of all timers: when the driver must call `handle_timeout` next.
    pub fn next_timeout(&self) -> Option<Instant> {
        self.at.iter().flatten().min().copied()
    }

    /// Whether `timer` is set and due at `now` (a deadline is due at its instant, not after).
    pub fn is_expired(&self, timer: T, now: Instant) -> bool {
        self.get(timer).is_some_and(|at| at <= now)
    }

    /// The timers due at `now`, in [`Timer::ALL`] order.
    pub fn expired(&self, now: Instant) -> impl Iterator<Item = T> + '_ {
        T::ALL
            .into_iter()
            .filter(move |&timer| self.is_expired(timer, now))
    }
}

impl<T: Timer<N>, const N: usize> Default for TimerTable<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Timer<N>, const N: usize> fmt::Debug for TimerTable<T, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map()
            .entries(
                T::ALL
                    .into_iter()
                    .filter_map(|t| self.get(t).map(|at| (t, at))),
            )
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testkit::check_timer_slots as check_indices;

    crate::timers! {
        enum Demo {
            Retry,
            Idle,
            Report,
        }
    }

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    #[test]
    fn every_timer_enum_of_the_crate_has_one_slot_per_timer() {
        check_indices::<Demo, 3>();
        check_indices::<crate::link::retry::ExchangeTimer, 1>();
        check_indices::<crate::transfer::receiver::ReceiverTimer, 1>();
    }

    #[test]
    fn a_new_table_never_fires() {
        let table = TimerTable::<Demo, 3>::new();
        assert_eq!(table.next_timeout(), None);
        assert_eq!(table.expired(Instant::from_micros(u64::MAX)).count(), 0);
    }

    #[test]
    fn nothing_at_t_minus_1_the_timer_at_t() {
        let mut table = TimerTable::<Demo, 3>::new();
        table.set(Demo::Retry, at(500));
        assert_eq!(table.next_timeout(), Some(at(500)));
        assert!(!table.is_expired(Demo::Retry, at(499)));
        assert_eq!(table.expired(at(499)).count(), 0);
        assert!(table.is_expired(Demo::Retry, at(500)));
        assert_eq!(table.expired(at(500)).collect::<Vec<_>>(), [Demo::Retry]);
        // Late is still due.
        assert!(table.is_expired(Demo::Retry, at(10_000)));
    }

    #[test]
    fn next_timeout_is_the_earliest_set_timer() {
        let mut table = TimerTable::<Demo, 3>::new();
        table.set(Demo::Idle, at(3000));
        table.set(Demo::Report, at(1000));
        table.set(Demo::Retry, at(500));
        assert_eq!(table.next_timeout(), Some(at(500)));
        table.stop(Demo::Retry);
        assert_eq!(table.get(Demo::Retry), None);
        assert_eq!(table.next_timeout(), Some(at(1000)));
        // Setting again moves the timer.
        table.set(Demo::Report, at(4000));
        assert_eq!(table.next_timeout(), Some(at(3000)));
        table.set_or_stop(Demo::Idle, None);
        assert_eq!(table.next_timeout(), Some(at(4000)));
    }

    #[test]
    fn expired_reports_every_due_timer_in_enum_order() {
        let mut table = TimerTable::<Demo, 3>::new();
        table.set(Demo::Report, at(100));
        table.set(Demo::Retry, at(200));
        table.set(Demo::Idle, at(300));
        assert_eq!(table.expired(at(99)).count(), 0);
        assert_eq!(table.expired(at(100)).collect::<Vec<_>>(), [Demo::Report]);
        assert_eq!(
            table.expired(at(250)).collect::<Vec<_>>(),
            [Demo::Retry, Demo::Report]
        );
        assert_eq!(
            table.expired(at(300)).collect::<Vec<_>>(),
            [Demo::Retry, Demo::Idle, Demo::Report]
        );
        assert_eq!(
            format!("{table:?}"),
            "{Retry: Instant(200000), Idle: Instant(300000), Report: Instant(100000)}"
        );
    }
}
