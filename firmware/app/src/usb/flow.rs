//! The console's flow control towards a host that types faster than it
//! reads: which host counts as not reading, and the closers owed to the
//! lines it typed meanwhile.

use crate::command::CommandLink;
use crate::outbound::Outbound;

/// Whether the host reads its replies: it counts as not reading from a
/// [`HOST_STALL`](super::HOST_STALL) in which the writer took no line
/// until the writer takes one again.
#[derive(Default)]
pub(super) struct HostReading {
    /// [`Outbound::lines_taken`] when the host was found not reading.
    stalled_at: Option<u32>,
}

impl HostReading {
    /// Whether the host counts as not reading (it has read nothing since
    /// it was found so).
    pub(super) fn not_reading(&mut self, out: &Outbound) -> bool {
        match self.stalled_at {
            Some(taken) if taken == out.lines_taken() => true,
            _ => {
                self.stalled_at = None;
                false
            }
        }
    }

    /// The host let a [`HOST_STALL`](super::HOST_STALL) pass without
    /// reading.
    pub(super) fn stalled(&mut self, out: &Outbound) {
        self.stalled_at = Some(out.lines_taken());
    }
}

/// Closers owed to lines that arrived while the outbound queue had no room
/// for their replies (a host typing ahead but not reading), in order, as
/// runs: `ok` for a `stop` (carried out at once), `error:` for any other
/// line (not run).
#[derive(Default)]
pub(super) struct OwedClosers {
    /// `(ok, count)` runs, oldest first.
    runs: heapless::Deque<(bool, u32), 8>,
}

/// Reply of a line that was not run because its reply could not be queued.
const NOT_RUN: &str =
    "not run: the host was not reading replies (output queue full); send it again";

impl OwedClosers {
    pub(super) fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Owes one closer (`ok` when `ok`); `false` when there is no room
    /// left to remember it (nothing recorded).
    pub(super) fn owe(&mut self, ok: bool) -> bool {
        if let Some((last_ok, count)) = self.runs.back_mut()
            && *last_ok == ok
        {
            *count = count.saturating_add(1);
            return true;
        }
        self.runs.push_back((ok, 1)).is_ok()
    }

    /// Queues as many owed closers, oldest first, as the outbound queue has
    /// room for.
    pub(super) fn pay(&mut self, link: &CommandLink) {
        while link.outbound.has_closer_room() {
            let Some((ok, count)) = self.runs.front_mut() else {
                return;
            };
            let reply = link.direct_reply();
            if *ok {
                reply.ok();
            } else {
                reply.error(NOT_RUN);
            }
            *count -= 1;
            if *count == 0 {
                self.runs.pop_front();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outbound::LineKind;

    #[test]
    fn a_host_counts_as_not_reading_until_the_writer_takes_a_line() {
        let out = Outbound::new();
        let mut reading = HostReading::default();
        assert!(!reading.not_reading(&out));
        out.push(LineKind::Ok, "");
        out.push(LineKind::Ok, "");
        reading.stalled(&out);
        assert!(reading.not_reading(&out));
        out.push(LineKind::Ok, "");
        assert!(reading.not_reading(&out), "queuing is not reading");
        assert!(out.take().is_some());
        assert!(!reading.not_reading(&out), "the host read a line");
        assert!(!reading.not_reading(&out));
    }

    #[test]
    fn owed_closers_are_paid_in_order_as_runs() {
        let link = CommandLink::new();
        let mut owed = OwedClosers::default();
        for ok in [false, false, true, false] {
            assert!(owed.owe(ok));
        }
        owed.pay(&link);
        assert!(owed.is_empty());
        let kinds: [Option<LineKind>; 5] =
            core::array::from_fn(|_| link.outbound.take().map(|l| l.kind));
        assert_eq!(
            kinds,
            [
                Some(LineKind::Error),
                Some(LineKind::Error),
                Some(LineKind::Ok),
                Some(LineKind::Error),
                None
            ]
        );
    }
}
