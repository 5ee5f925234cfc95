use super::*;
use proptest::prelude::*;

#[test]
fn position_and_half_from_ndtr() {
    let ring = Ring::new(4);
    assert_eq!(ring.samples(), 8);
    assert_eq!(ring.position(8), Some(0));
    assert_eq!(ring.position(5), Some(3));
    assert_eq!(ring.position(4), Some(4));
    assert_eq!(ring.position(1), Some(7));
    assert_eq!(ring.position(0), None);
    assert_eq!(ring.position(9), None);
    assert_eq!(ring.range(0), 0..4);
    assert_eq!(ring.range(1), 4..8);
    assert_eq!(Ring::new(0).samples(), 2);
}

#[test]
fn reading_half_catches_a_boundary_the_interrupt_has_not_counted() {
    let ring = Ring::new(4);
    // Counted half 6 (physical 0); the DMA is still in it.
    assert_eq!(ring.reading_half(6, 6), Some(6));
    // NDTR already shows physical half 1: half 7, interrupt pending.
    assert_eq!(ring.reading_half(6, 4), Some(7));
    assert_eq!(ring.reading_half(u32::MAX, 8), Some(0), "wraps");
    assert_eq!(ring.reading_half(6, 0), None);
}

#[test]
fn slot_waits_writes_or_reports_late_halves() {
    assert_eq!(slot(5, 3), Slot::Wait);
    assert_eq!(slot(5, 4), Slot::Free);
    assert_eq!(slot(5, 5), Slot::Late { halves: 1 });
    assert_eq!(slot(5, 7), Slot::Late { halves: 3 });
    // Across the wrap of the counters.
    assert_eq!(slot(1, u32::MAX), Slot::Wait);
    assert_eq!(slot(0, u32::MAX), Slot::Free);
    assert_eq!(slot(u32::MAX, 1), Slot::Late { halves: 3 });
}

#[test]
fn the_interrupt_flags_unwritten_halves_but_not_a_held_replay() {
    assert!(!underrun_at_start(4, 5, false));
    assert!(underrun_at_start(5, 5, false));
    assert!(underrun_at_start(6, 5, false));
    assert!(!underrun_at_start(6, 5, true));
    assert!(underrun_at_start(0, u32::MAX, false), "wraps");
}

#[test]
fn lockstep_allows_one_item_either_way_round_the_wrap() {
    let ring = Ring::new(4);
    assert!(ring.in_lockstep(5, 5));
    assert!(ring.in_lockstep(5, 4));
    assert!(ring.in_lockstep(1, 8), "last item vs wrapped to 0");
    assert!(!ring.in_lockstep(6, 4));
    assert!(!ring.in_lockstep(0, 4), "a stopped stream");
}

#[test]
fn the_cursor_primes_two_halves_then_follows_the_dma() {
    let mut c = Cursor::new();
    assert!(!c.started());
    assert_eq!(c.physical(), 0);
    assert!(!c.primed());
    assert_eq!(c.physical(), 1);
    assert!(c.primed(), "starts with both halves written");
    // The DMA reads half 0: half 2 (physical 0) waits for it.
    assert_eq!(c.claim(0), Claim::Wait);
    assert_eq!(
        c.claim(1),
        Claim::Write {
            physical: 0,
            late: 0
        }
    );
    assert_eq!(c.commit(), 3, "halves 0..3 written");
    assert!(!c.check(1), "the DMA is still before it");
    assert!(c.check(2), "the DMA began it during the copy");
    // Three halves late: written after the one the DMA reads.
    assert_eq!(
        c.claim(5),
        Claim::Write {
            physical: 0,
            late: 3
        }
    );
    assert_eq!(c.commit(), 7);
    c.reset();
    assert_eq!(c, Cursor::new());
}

proptest! {
    /// The refill (the cursor at each hand-over) and the interrupt (a
    /// check at each half start) count the same underruns, whatever the
    /// refill's timing and however late the interrupt sees a boundary.
    #[test]
    fn refill_and_interrupt_agree_on_underruns(
        half_len in 1usize..8,
        computes in prop::collection::vec(0usize..40, 1..60),
        isr_lag in prop::collection::vec(any::<bool>(), 60),
    ) {
        let ring = Ring::new(half_len);
        let n = half_len;
        let mut cursor = Cursor::new();
        prop_assert!(!cursor.primed() && cursor.primed());
        // Time in samples; the DMA reads sample t mod len of half t / n.
        let (mut t, mut written) = (0usize, 2u32);
        let (mut isr_seen, mut isr_underruns, mut refill_underruns) = (0u32, 0u32, 0u32);
        let advance = |t: &mut usize, to: usize, written: u32, isr_seen: &mut u32, count: &mut u32| {
            while *t < to {
                *t += 1;
                if t.is_multiple_of(n) {
                    *isr_seen = isr_seen.wrapping_add(1);
                    if underrun_at_start(*isr_seen, written, false) {
                        *count += 1;
                    }
                }
            }
        };
        for (k, &compute) in computes.iter().enumerate() {
            let to = t + compute;
            advance(&mut t, to, written, &mut isr_seen, &mut isr_underruns);
            let late = loop {
                // The interrupt may not have run for a boundary just crossed.
                let counted = if isr_lag[k] && t.is_multiple_of(n) { isr_seen.wrapping_sub(1) } else { isr_seen };
                let ndtr = (ring.samples() - t % ring.samples()) as u32;
                let reading = ring.reading_half(counted, ndtr).unwrap();
                prop_assert_eq!(reading, (t / n) as u32);
                match cursor.claim(reading) {
                    Claim::Wait => {
                        let boundary = (t / n + 1) * n;
                        advance(&mut t, boundary, written, &mut isr_seen, &mut isr_underruns);
                    }
                    Claim::Write { physical, late } => {
                        prop_assert_ne!(physical, (t / n) % 2, "never the half the DMA reads");
                        break late;
                    }
                }
            };
            refill_underruns += late;
            written = cursor.commit();
            prop_assert!(!cursor.check((t / n) as u32), "an instant copy is in time");
        }
        prop_assert_eq!(refill_underruns, isr_underruns);
    }
}
