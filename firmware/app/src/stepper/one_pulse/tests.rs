extern crate std;

use proptest::prelude::*;

use super::*;

/// The reference board's TIM1 clock (APB2 timers), Hz.
const TIM1_HZ: u32 = 168_000_000;

fn signals(pulse_ns: u32, dir_setup_ns: u32) -> DriverSignals {
    DriverSignals {
        pulse_ns,
        dir_setup_ns,
        enable_active_high: false,
    }
}

/// A model of the timer's channel output (RM0090: the counter runs 0, 1,
/// …, ARR, then the update stops it at 0 in one-pulse mode; OCxM decides
/// the output at each count): the counts from the start at which the
/// output rises and falls, if it pulses at all. PWM mode 2's output only
/// ever switches on as the count grows, so the rising count is found by
/// bisection.
fn channel_output(pulse: &OnePulse, axis: usize) -> Option<(u32, u32)> {
    let mode = (pulse.ccmr1 >> OCM_SHIFT[axis]) & 0b111;
    let high_at = |cnt: u32| match mode {
        OCM_PWM_MODE_2 => cnt >= u32::from(pulse.compare),
        OCM_FORCE_INACTIVE => false,
        other => panic!("unexpected OCxM {other:#b}"),
    };
    // Stopped at 0 before the start and after the update: must be low.
    assert!(!high_at(0), "high while the counter rests at 0");
    let reload = u32::from(pulse.reload);
    if !high_at(reload) {
        return None;
    }
    let (mut low, mut high) = (0, reload);
    while high - low > 1 {
        let mid = low + (high - low) / 2;
        if high_at(mid) { high = mid } else { low = mid }
    }
    // High from `high` through ARR; low again at the update.
    Some((high, reload + 1))
}

#[test]
fn the_default_signals_on_tim1() {
    // 2.5 µs and 5 µs at 168 MHz: 420 and 840 counts, no prescaler.
    let t = OnePulseTiming::new(TIM1_HZ, signals(2_500, 5_000));
    assert_eq!(t.prescaler(), 0);
    let changed = t.event([true, true], true).unwrap();
    assert_eq!((changed.compare, changed.reload), (840, 840 + 420 - 1));
    let same = t.event([true, false], false).unwrap();
    assert_eq!((same.compare, same.reload), (1, 420));
    assert_eq!(t.counts_ns(changed.rise_counts()), 5_000);
    assert_eq!(
        t.counts_ns(changed.fall_counts()) - t.counts_ns(changed.rise_counts()),
        2_500
    );
    assert_eq!(channel_output(&changed, 0), Some((840, 1260)));
    assert_eq!(channel_output(&same, 0), Some((1, 421)));
    assert_eq!(channel_output(&same, 1), None);
}

#[test]
fn ccmr1_is_rm0090s_layout() {
    let t = OnePulseTiming::new(TIM1_HZ, signals(2_500, 5_000));
    // OC1M bits 6:4, OC2M bits 14:12; 111 PWM mode 2, 100 force inactive.
    assert_eq!(CCMR1_IDLE, 0x4040);
    assert_eq!(t.event([true, false], false).unwrap().ccmr1, 0x4070);
    assert_eq!(t.event([false, true], false).unwrap().ccmr1, 0x7040);
    assert_eq!(t.event([true, true], true).unwrap().ccmr1, 0x7070);
    let both = t.event([true, true], false).unwrap();
    assert!(both.pulses(0) && both.pulses(1));
}

#[test]
fn no_stepping_axis_leaves_the_timer_alone() {
    let t = OnePulseTiming::new(TIM1_HZ, signals(2_500, 5_000));
    assert_eq!(t.event([false, false], true), None);
    assert_eq!(t.event([false, false], false), None);
}

#[test]
fn long_signals_take_a_prescaler() {
    // 100 µs + 100 µs at 168 MHz is 33 600 counts: fits; at 500 MHz it is
    // 100 000 and needs a divisor of 2.
    let fits = OnePulseTiming::new(TIM1_HZ, signals(100_000, 100_000));
    assert_eq!(fits.prescaler(), 0);
    let t = OnePulseTiming::new(500_000_000, signals(100_000, 100_000));
    assert_eq!(t.prescaler(), 1);
    let p = t.event([true, true], true).unwrap();
    assert_eq!((p.compare, p.reload), (25_000, 49_999));
}

#[test]
fn zero_times_are_one_count_and_never_high_at_rest() {
    let t = OnePulseTiming::new(TIM1_HZ, signals(0, 0));
    for changed in [false, true] {
        let p = t.event([true, true], changed).unwrap();
        assert_eq!((p.compare, p.reload), (1, 1));
        assert_eq!(channel_output(&p, 0), Some((1, 2)));
    }
}

#[test]
fn beyond_500_mhz_seconds_are_clamped_to_the_counter() {
    let t = OnePulseTiming::new(u32::MAX, signals(u32::MAX, u32::MAX));
    assert_eq!(t.prescaler(), u16::MAX);
    let p = t.event([true, true], true).unwrap();
    assert!(p.compare >= 1 && p.compare <= p.reload);
    assert!(channel_output(&p, 1).is_some());
}

/// `counts` at `divisor` (PSC + 1) on a `hz` clock last at least `ns`:
/// counts · divisor / hz ≥ ns · 1e-9, exactly.
fn at_least(counts: u32, divisor: u64, hz: u32, ns: u32) -> bool {
    u128::from(counts) * u128::from(divisor) * 1_000_000_000 >= u128::from(ns) * u128::from(hz)
}

/// … and at most one count longer.
fn within_one_count(counts: u32, divisor: u64, hz: u32, ns: u32) -> bool {
    u128::from(counts - 1) * u128::from(divisor) * 1_000_000_000 <= u128::from(ns) * u128::from(hz)
}

fn fits(hz: u32, s: DriverSignals, divisor: u64) -> bool {
    let c = |ns: u32| {
        (u128::from(ns) * u128::from(hz))
            .div_ceil(1_000_000_000 * u128::from(divisor))
            .max(1)
    };
    c(s.pulse_ns) + c(s.dir_setup_ns) <= 1 << 16
}

fn check(hz: u32, s: DriverSignals) {
    let t = OnePulseTiming::new(hz, s);
    let divisor = u64::from(t.prescaler()) + 1;
    // The smallest prescaler that fits.
    assert!(fits(hz, s, divisor));
    assert!(divisor == 1 || !fits(hz, s, divisor - 1), "{t:?}");
    for step in [[true, false], [false, true], [true, true]] {
        for changed in [false, true] {
            let p = t.event(step, changed).unwrap();
            for (axis, &steps) in step.iter().enumerate() {
                let Some((rise, fall)) = channel_output(&p, axis) else {
                    assert!(!steps, "{p:?}: axis {axis} steps");
                    continue;
                };
                assert!(steps, "{p:?}: axis {axis} does not step");
                let high = fall - rise;
                assert!(at_least(high, divisor, hz, s.pulse_ns), "{p:?}");
                assert!(within_one_count(high, divisor, hz, s.pulse_ns), "{p:?}");
                if changed {
                    assert!(at_least(rise, divisor, hz, s.dir_setup_ns), "{p:?}");
                    assert!(within_one_count(rise, divisor, hz, s.dir_setup_ns));
                } else {
                    assert_eq!(rise, 1);
                }
            }
        }
    }
}

proptest! {
    /// The settings' ranges (pulse 0.5–100 µs, setup 0–100 µs) on TIM1:
    /// never shorter than configured, at most one count longer, no
    /// prescaler needed.
    #[test]
    fn settings_range_on_tim1(pulse_ns in 500u32..=100_000, setup_ns in 0u32..=100_000) {
        check(TIM1_HZ, signals(pulse_ns, setup_ns));
        prop_assert_eq!(OnePulseTiming::new(TIM1_HZ, signals(pulse_ns, setup_ns)).prescaler(), 0);
    }

    /// Any signals on any timer clock up to 500 MHz: the counts fit 16
    /// bits with the smallest prescaler, and the bounds hold.
    #[test]
    fn any_signals_any_clock(
        hz in 1_000_000u32..=500_000_000,
        pulse_ns in any::<u32>(),
        setup_ns in any::<u32>(),
    ) {
        check(hz, signals(pulse_ns, setup_ns));
    }
}
