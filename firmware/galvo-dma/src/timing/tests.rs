use super::*;
use proptest::prelude::*;

const TIM8_HZ: u32 = 168_000_000;

#[test]
fn the_default_100_khz_needs_no_prescaler() {
    let s = timer_setting(TIM8_HZ, 10e-6).unwrap();
    assert_eq!(
        s,
        TimerSetting {
            prescaler: 0,
            reload: 1679
        }
    );
    assert_eq!(s.period_ticks(), 1680);
    assert!((s.period_s(TIM8_HZ) - 10e-6).abs() < 1e-15);
}

#[test]
fn a_slow_clock_takes_the_smallest_prescaler_that_fits() {
    // 1 ms = 168 000 ticks: divided by 3, 56 000 counts.
    let s = timer_setting(TIM8_HZ, 1e-3).unwrap();
    assert_eq!(
        s,
        TimerSetting {
            prescaler: 2,
            reload: 55_999
        }
    );
    // Exactly 65 536 ticks still fits without a prescaler.
    let s = timer_setting(65_536, 1.0).unwrap();
    assert_eq!(
        s,
        TimerSetting {
            prescaler: 0,
            reload: u16::MAX
        }
    );
}

#[test]
fn impossible_periods_are_refused() {
    for bad in [0.0, -1e-5, f64::NAN, f64::INFINITY, 1e-9, 1e3] {
        assert_eq!(timer_setting(TIM8_HZ, bad), None, "{bad}");
    }
}

proptest! {
    /// Within half a prescaled tick of the request over the settable
    /// range (5 µs to 1 ms).
    #[test]
    fn the_setting_is_the_nearest_tick(period_us in 5.0f64..1000.0) {
        let s = timer_setting(TIM8_HZ, period_us * 1e-6).unwrap();
        let wanted = period_us * 1e-6 * f64::from(TIM8_HZ);
        let error = (f64::from(s.period_ticks()) - wanted).abs();
        prop_assert!(error <= f64::from(s.prescaler as u32 + 1) / 2.0 + 0.5 + 1e-6, "{s:?} {error}");
    }
}

#[test]
fn the_meter_keeps_the_worst_refill_without_the_wait() {
    let mut m = RefillMeter::new();
    assert_eq!(m.record(100, 500, 520), None, "start-up is not a refill");
    // Computed 1000 cycles, waited, copied 30.
    assert_eq!(m.record(1520, 9000, 9030), Some(1030));
    assert_eq!(m.record(9530, 9530, 9560), Some(530));
    assert_eq!(m.worst(), Some(1030));
    // Across the counter's wrap.
    let mut m = RefillMeter::new();
    m.record(0, 0, u32::MAX - 9);
    assert_eq!(m.record(90, 90, 100), Some(110));
}
