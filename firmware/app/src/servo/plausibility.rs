//! Plausibility of servo angle readings.
//!
//! The FashionStar response checksum is an 8-bit sum: two bit flips that
//! cancel (the same bit set in one byte and cleared in another, or the same
//! bit set in an angle byte and in the checksum) pass it. At a 10 % byte
//! corruption rate about one angle response in a thousand is wrong yet
//! valid, e.g. 1267 instead of 247 tenths. Before a reading may drive
//! arrival or fault logic it must therefore be physically possible:
//!
//! - inside the servo's configured range (widened by [`RANGE_SLACK_TENTHS`]
//!   and by the last accepted reading, so a servo that starts outside its
//!   range can still be brought in), and
//! - no farther from the last accepted reading than a servo can turn in the
//!   time between them: the SDK's 750 °/s limit plus 50 %
//!   ([`PLAUSIBLE_RATE_TENTHS_PER_S`]) plus [`JUMP_SLACK_TENTHS`] for the
//!   response latency.
//!
//! Without a recent accepted reading (at start, or once so much time has
//! passed that any angle could be reached) a reading is accepted only when
//! the next one confirms it (the same jump rule between the two). Rejected
//! readings are counted; [`IMPLAUSIBLE_RUN`] of them in a row is a fault.

use embassy_time::{Duration, Instant};

/// Fastest a FashionStar servo turns (vendor SDK limit), 0.1°/s.
pub const SDK_MAX_RATE_TENTHS_PER_S: u64 = 7_500;
/// Rate a reading may imply and still be believed: the SDK limit plus
/// 50 %, 0.1°/s.
pub const PLAUSIBLE_RATE_TENTHS_PER_S: u64 = SDK_MAX_RATE_TENTHS_PER_S * 3 / 2;
/// Jump always allowed between two readings (the angle is sampled up to a
/// frame time before the response arrives, plus sensor noise), 0.1°.
pub const JUMP_SLACK_TENTHS: u32 = 20;
/// How far beyond its configured range a reading may be (overshoot,
/// deadband), 0.1°.
pub const RANGE_SLACK_TENTHS: i32 = 50;
/// Largest angle a FashionStar single-turn reading can be, 0.1°.
pub const WIRE_LIMIT_TENTHS: i32 = 1_800;
/// Implausible readings in a row (across polls) that make a fault.
pub const IMPLAUSIBLE_RUN: u8 = 5;

/// What the filter made of one reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Verdict {
    /// Physically possible: use it.
    Accepted(i16),
    /// The first reading without a recent reference: kept as a candidate
    /// until the next reading confirms it (not counted as implausible).
    Unconfirmed,
    /// Impossible (out of range, or a jump no servo can make); counted.
    /// `run` is the number of implausible readings in a row.
    Implausible {
        /// Implausible readings in a row, this one included.
        run: u8,
    },
}

/// The largest jump, 0.1°, a servo can show between readings `elapsed`
/// apart.
pub fn max_jump_tenths(elapsed: Duration) -> u32 {
    let from_rate = elapsed
        .as_micros()
        .saturating_mul(PLAUSIBLE_RATE_TENTHS_PER_S)
        / 1_000_000;
    u32::try_from(from_rate)
        .unwrap_or(u32::MAX)
        .saturating_add(JUMP_SLACK_TENTHS)
}

/// Whether `elapsed` is so long that any angle could be reached.
fn reference_expired(elapsed: Duration) -> bool {
    max_jump_tenths(elapsed) >= 2 * WIRE_LIMIT_TENTHS as u32
}

/// Plausibility filter of one servo's readings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadingFilter {
    /// Configured range, 0.1° (inclusive).
    range_tenths: (i16, i16),
    /// Last accepted reading and when it was taken.
    last_good: Option<(i16, Instant)>,
    /// The last two in-envelope readings not accepted, newest first
    /// (candidates for confirmation; two, so that one corrupted reading
    /// cannot displace the good one before it).
    candidates: [Option<(i16, Instant)>; 2],
    /// Implausible readings in a row.
    run: u8,
}

impl ReadingFilter {
    /// A filter for a servo with this configured range (0.1°), no history.
    pub const fn new(range_tenths: (i16, i16)) -> Self {
        Self {
            range_tenths,
            last_good: None,
            candidates: [None; 2],
            run: 0,
        }
    }

    /// Sets the configured range, 0.1° (kept history stays).
    pub fn set_range(&mut self, range_tenths: (i16, i16)) {
        self.range_tenths = range_tenths;
    }

    /// Forgets the history (the servo was replaced, or its id changed).
    pub fn reset(&mut self) {
        *self = Self::new(self.range_tenths);
    }

    /// The last accepted reading, 0.1°.
    pub fn last_good(&self) -> Option<i16> {
        self.last_good.map(|(a, _)| a)
    }

    /// Whether `reading` lies in the range a reading may have: the
    /// configured range, widened by the slack and by the last accepted
    /// reading, and never beyond the wire limit.
    pub fn in_envelope(&self, reading: i16) -> bool {
        let (lo, hi) = self.range_tenths;
        let (mut lo, mut hi) = (i32::from(lo), i32::from(hi));
        if let Some((good, _)) = self.last_good {
            lo = lo.min(i32::from(good));
            hi = hi.max(i32::from(good));
        }
        let r = i32::from(reading);
        r >= (lo - RANGE_SLACK_TENTHS).max(-WIRE_LIMIT_TENTHS)
            && r <= (hi + RANGE_SLACK_TENTHS).min(WIRE_LIMIT_TENTHS)
    }

    /// Judges `reading` taken at `now`.
    ///
    /// Accepted when inside the envelope and within the physical jump of
    /// the last accepted reading, or of one of the last two readings that
    /// were not accepted (two readings that agree outvote a reference that
    /// was itself a corrupted reading, and confirm the first reading when
    /// there is no recent reference).
    pub fn judge(&mut self, reading: i16, now: Instant) -> Verdict {
        let recent = |from: Option<(i16, Instant)>| {
            from.filter(|(_, at)| !reference_expired(now.saturating_duration_since(*at)))
        };
        let within = |from: (i16, Instant)| {
            let jump = (i32::from(reading) - i32::from(from.0)).unsigned_abs();
            jump <= max_jump_tenths(now.saturating_duration_since(from.1))
        };
        let reference = recent(self.last_good);
        let candidates = self.candidates.map(recent);
        let in_envelope = self.in_envelope(reading);
        let confirmed = candidates.iter().flatten().any(|c| within(*c));
        if in_envelope && (reference.is_some_and(within) || confirmed) {
            self.last_good = Some((reading, now));
            self.candidates = [None; 2];
            self.run = 0;
            return Verdict::Accepted(reading);
        }
        if in_envelope {
            let [newest, _] = self.candidates;
            self.candidates = [Some((reading, now)), newest];
            if reference.is_none() && candidates.iter().all(Option::is_none) {
                return Verdict::Unconfirmed;
            }
        }
        self.run = self.run.saturating_add(1);
        Verdict::Implausible { run: self.run }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;
    use fashionstar::{Message, Response, ResponseDecoder};
    use proptest::prelude::*;

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    const RANGE: (i16, i16) = (-1350, 1350);

    #[test]
    fn the_reported_corruption_is_rejected() {
        let mut f = ReadingFilter::new(RANGE);
        assert_eq!(f.judge(247, at(0)), Verdict::Unconfirmed);
        assert_eq!(f.judge(247, at(10)), Verdict::Accepted(247));
        // 1267 ten ms later is 10 200 °/s.
        assert_eq!(f.judge(1267, at(20)), Verdict::Implausible { run: 1 });
        assert_eq!(f.judge(248, at(30)), Verdict::Accepted(248));
    }

    #[test]
    fn out_of_range_readings_are_rejected_and_a_run_is_counted() {
        let mut f = ReadingFilter::new(RANGE);
        f.judge(0, at(0));
        assert_eq!(f.judge(0, at(10)), Verdict::Accepted(0));
        // Far outside the ±135° range (and the wire limit).
        for (i, r) in [1_500i16, -1_500, 3_000, -32_000, 1_500]
            .into_iter()
            .enumerate()
        {
            assert_eq!(
                f.judge(r, at(1_000 + 10 * i as u64)),
                Verdict::Implausible { run: i as u8 + 1 }
            );
        }
    }

    #[test]
    fn a_servo_that_starts_outside_its_range_is_confirmed_and_brought_in() {
        let mut f = ReadingFilter::new(RANGE);
        assert_eq!(f.judge(1_500, at(0)), Verdict::Implausible { run: 1 });
        // Not confirmable outside the envelope: a real out-of-range
        // servo keeps reading out of range and is a fault.
        assert!(matches!(
            f.judge(1_500, at(10)),
            Verdict::Implausible { .. }
        ));
        let mut g = ReadingFilter::new(RANGE);
        assert_eq!(g.judge(1_390, at(0)), Verdict::Unconfirmed);
        assert_eq!(g.judge(1_388, at(10)), Verdict::Accepted(1_388));
        assert_eq!(g.judge(1_300, at(20)), Verdict::Accepted(1_300));
    }

    #[test]
    fn fast_but_possible_moves_are_accepted() {
        let mut f = ReadingFilter::new(RANGE);
        f.judge(-1_000, at(0));
        f.judge(-1_000, at(10));
        // 750 °/s for 100 ms = 75° = 750 tenths.
        let mut angle = -1_000i16;
        for k in 1..=10u64 {
            angle += 75;
            assert_eq!(f.judge(angle, at(10 + 10 * k)), Verdict::Accepted(angle));
        }
    }

    #[test]
    fn a_stale_reference_needs_confirmation_again() {
        let mut f = ReadingFilter::new(RANGE);
        f.judge(0, at(0));
        assert_eq!(f.judge(0, at(10)), Verdict::Accepted(0));
        // A second later any angle is reachable: confirm first.
        assert_eq!(f.judge(1_200, at(1_010)), Verdict::Unconfirmed);
        assert_eq!(f.judge(1_201, at(1_020)), Verdict::Accepted(1_201));
    }

    /// An angle response frame for `angle`, with up to `flips` pairs of
    /// bit flips chosen so the 8-bit checksum still holds (a bit set in
    /// one byte and cleared in another, or the same bit set in a byte and
    /// in the checksum).
    fn corrupted_frame(angle: i16, pairs: &[(usize, usize, u8)]) -> Vec<u8> {
        let mut frame = Response::Angle {
            id: 0,
            angle_tenths_deg: angle,
        }
        .to_frame()
        .unwrap()
        .to_vec();
        let last = frame.len() - 1;
        for &(a, b, bit) in pairs {
            // Only the payload angle bytes and the checksum: a flip in
            // the header, code, length or id makes another frame.
            let pick = |i: usize| [last - 2, last - 1, last][i % 3];
            let (a, b) = (pick(a), pick(b));
            if a == b {
                continue;
            }
            let mask = 1u8 << (bit % 8);
            let (a, b) = if b == last { (b, a) } else { (a, b) };
            if a == last {
                // Same bit set in a data byte and in the checksum.
                if frame[b] & mask == 0 && frame[a] & mask == 0 {
                    frame[b] |= mask;
                    frame[a] |= mask;
                }
            } else if frame[a] & mask == 0 && frame[b] & mask != 0 {
                frame[a] |= mask;
                frame[b] &= !mask;
            }
        }
        frame
    }

    fn decode(frame: &[u8]) -> Option<i16> {
        let mut d = ResponseDecoder::new();
        frame.iter().find_map(|&b| match d.feed(b) {
            Some(Ok(Response::Angle {
                angle_tenths_deg, ..
            })) => Some(angle_tenths_deg),
            _ => None,
        })
    }

    #[test]
    fn the_corruption_generator_keeps_the_checksum_and_changes_the_angle() {
        assert_eq!(decode(&corrupted_frame(247, &[])), Some(247));
        // The reported case: bit 2 set in the high byte, cleared in the low.
        assert_eq!(decode(&corrupted_frame(247, &[(1, 0, 2)])), Some(1267));
        // Bit 0 set in the low byte and in the checksum.
        let small = decode(&corrupted_frame(246, &[(0, 2, 0)]));
        assert_eq!(small, Some(247));
    }

    proptest! {
        /// A servo moving at up to the SDK's 750 °/s inside its range,
        /// polled every 2..40 ms, with checksum-preserving corruption:
        /// every accepted reading is inside the envelope and within the
        /// physical jump of the previous accepted one (or, without a
        /// recent one, of the reading before it); a corrupted reading
        /// beyond the physical jump from the truth is never accepted
        /// after a clean one; and the servo's real readings keep being
        /// accepted (no fault from isolated corruption).
        #[test]
        fn accepted_readings_are_physically_possible(
            start in -1_300i16..1_300,
            steps in prop::collection::vec((2u64..40, -1.0f64..1.0, any::<bool>()), 20..200),
            corruptions in prop::collection::vec(
                (0.0f64..1.0, prop::collection::vec((0usize..3, 0usize..3, 0u8..8), 1..3)),
                200,
            ),
        ) {
            let mut f = ReadingFilter::new(RANGE);
            let mut truth = f64::from(start);
            let mut now = 0u64;
            let mut last_accepted: Option<(i16, u64)> = None;
            // Previous decoded reading: value, time, corrupted, accepted.
            let mut previous: Option<(i16, u64, bool, bool)> = None;
            // The last two in-envelope readings not accepted, newest first.
            let mut unaccepted: [Option<(i16, u64)>; 2] = [None; 2];
            let mut run_of_rejects = 0;
            for (i, &(dt, speed, hold)) in steps.iter().enumerate() {
                now += dt;
                if !hold {
                    // 750 °/s = 7.5 tenths per ms, inside the range.
                    truth = (truth + speed * 7.5 * dt as f64).clamp(-1_350.0, 1_350.0);
                }
                let true_reading = truth.round() as i16;
                let (p, pairs) = &corruptions[i % corruptions.len()];
                // Isolated corruption: never two in a row.
                let corrupt_now = *p < 0.3 && previous.is_none_or(|(_, _, c, _)| !c);
                let frame = if corrupt_now {
                    corrupted_frame(true_reading, pairs)
                } else {
                    corrupted_frame(true_reading, &[])
                };
                let Some(reading) = decode(&frame) else {
                    previous = None;
                    continue;
                };
                let corrupted = reading != true_reading;
                let verdict = f.judge(reading, at(now));
                let accepted = matches!(verdict, Verdict::Accepted(_));
                if let Verdict::Accepted(a) = verdict {
                    prop_assert!(f.in_envelope(a));
                    let recent = |t: u64| !reference_expired(Duration::from_millis(now - t));
                    let jump_ok = |(g, t): (i16, u64)| {
                        recent(t)
                            && (i32::from(a) - i32::from(g)).unsigned_abs()
                                <= max_jump_tenths(Duration::from_millis(now - t))
                    };
                    prop_assert!(
                        last_accepted.is_some_and(jump_ok)
                            || unaccepted.iter().flatten().any(|c| jump_ok(*c)),
                        "accepted {} without a physically consistent reading before it", a
                    );
                    if corrupted && previous.is_some_and(|(_, _, c, acc)| !c && acc) {
                        let dt = now - previous.map(|(_, t, _, _)| t).unwrap_or(now);
                        let off = (i32::from(a) - i32::from(true_reading)).unsigned_abs();
                        prop_assert!(
                            off <= 2 * max_jump_tenths(Duration::from_millis(dt)),
                            "accepted {} for {}", a, true_reading
                        );
                    }
                    last_accepted = Some((a, now));
                    unaccepted = [None; 2];
                    run_of_rejects = 0;
                } else {
                    if f.in_envelope(reading) {
                        unaccepted = [Some((reading, now)), unaccepted[0]];
                    }
                    run_of_rejects += 1;
                }
                // Isolated corruption never makes a run that faults.
                prop_assert!(run_of_rejects < usize::from(IMPLAUSIBLE_RUN), "{:?}", verdict);
                previous = Some((reading, now, corrupted, accepted));
            }
        }
    }
}
