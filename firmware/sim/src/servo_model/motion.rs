//! Motion profile of a simulated servo: a trapezoidal velocity profile in
//! time (accelerate for `t_acc`, cruise, decelerate for `t_dec`); with no
//! acceleration or deceleration phase it is a linear move.

/// One move from `from_deg` to `to_deg` starting at `start_us`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    start_us: f64,
    from_deg: f64,
    to_deg: f64,
    t_acc_us: f64,
    t_cruise_us: f64,
    t_dec_us: f64,
}

/// Non-negative and finite, else 0.
fn duration(t_us: f64) -> f64 {
    if t_us.is_finite() && t_us > 0.0 {
        t_us
    } else {
        0.0
    }
}

impl Motion {
    /// Standing still at `at_deg`.
    pub fn hold(at_deg: f64) -> Self {
        Self::trapezoid(0.0, at_deg, at_deg, 0.0, 0.0, 0.0)
    }

    /// Accelerate for `t_acc_us`, cruise for `t_cruise_us`, decelerate for
    /// `t_dec_us`; the cruise speed follows from the distance.
    pub fn trapezoid(
        start_us: f64,
        from_deg: f64,
        to_deg: f64,
        t_acc_us: f64,
        t_cruise_us: f64,
        t_dec_us: f64,
    ) -> Self {
        Self {
            start_us,
            from_deg,
            to_deg,
            t_acc_us: duration(t_acc_us),
            t_cruise_us: duration(t_cruise_us),
            t_dec_us: duration(t_dec_us),
        }
    }

    /// Arrive after exactly `interval_us`. Acceleration and deceleration
    /// phases longer than the interval together are shrunk in proportion.
    pub fn by_interval(
        start_us: f64,
        from_deg: f64,
        to_deg: f64,
        interval_us: f64,
        t_acc_us: f64,
        t_dec_us: f64,
    ) -> Self {
        let total = duration(interval_us);
        let (mut acc, mut dec) = (duration(t_acc_us), duration(t_dec_us));
        if acc + dec > total {
            let k = total / (acc + dec);
            acc *= k;
            dec *= k;
        }
        let cruise = total - acc - dec;
        Self::trapezoid(start_us, from_deg, to_deg, acc, cruise, dec)
    }

    /// Cruise at `velocity_deg_s` (> 0) with the given acceleration and
    /// deceleration times; a move too short to reach that velocity becomes
    /// a triangle with the same accelerations.
    pub fn by_velocity(
        start_us: f64,
        from_deg: f64,
        to_deg: f64,
        velocity_deg_s: f64,
        t_acc_us: f64,
        t_dec_us: f64,
    ) -> Self {
        let v = velocity_deg_s / 1e6; // °/µs
        let (mut acc, mut dec) = (duration(t_acc_us), duration(t_dec_us));
        let distance = (to_deg - from_deg).abs();
        if !(v.is_finite() && v > 0.0) {
            return Self::hold(from_deg);
        }
        let ramp_distance = v * (acc + dec) / 2.0;
        let cruise = if distance >= ramp_distance {
            (distance - ramp_distance) / v
        } else {
            // Peak velocity k·v, ramps k·t: ramp distance k²·ramp_distance.
            let k = (distance / ramp_distance).sqrt();
            acc *= k;
            dec *= k;
            0.0
        };
        Self::trapezoid(start_us, from_deg, to_deg, acc, cruise, dec)
    }

    /// Total duration, µs.
    pub fn duration_us(&self) -> f64 {
        self.t_acc_us + self.t_cruise_us + self.t_dec_us
    }

    /// When the move ends, µs.
    pub fn end_us(&self) -> f64 {
        self.start_us + self.duration_us()
    }

    /// Where the move goes, degrees.
    pub fn target_deg(&self) -> f64 {
        self.to_deg
    }

    /// Angle at `t_us`, degrees (exact, not quantised).
    pub fn angle_at(&self, t_us: f64) -> f64 {
        let t = t_us - self.start_us;
        let total = self.duration_us();
        if t >= total {
            return self.to_deg;
        }
        if t <= 0.0 {
            return self.from_deg;
        }
        let (ta, tc, td) = (self.t_acc_us, self.t_cruise_us, self.t_dec_us);
        let distance = self.to_deg - self.from_deg;
        // Peak (cruise) velocity, °/µs; total > 0 here, so the divisor is.
        let v = distance / (tc + (ta + td) / 2.0);
        let travelled = if t < ta {
            0.5 * v * t * t / ta
        } else if t < ta + tc {
            v * ta / 2.0 + v * (t - ta)
        } else {
            let left = total - t;
            distance - 0.5 * v * left * left / td
        };
        self.from_deg + travelled
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    #[test]
    fn linear_move() {
        let m = Motion::by_interval(1000.0, 0.0, 90.0, 1e6, 0.0, 0.0);
        assert_eq!(m.angle_at(0.0), 0.0);
        assert_eq!(m.angle_at(1000.0), 0.0);
        assert!((m.angle_at(501_000.0) - 45.0).abs() < 1e-9);
        assert_eq!(m.angle_at(1_001_000.0), 90.0);
        assert_eq!(m.end_us(), 1_001_000.0);
    }

    #[test]
    fn trapezoid_by_interval_is_symmetric_and_arrives_on_time() {
        let m = Motion::by_interval(0.0, 10.0, -30.0, 400_000.0, 100_000.0, 100_000.0);
        assert!((m.angle_at(200_000.0) + 10.0).abs() < 1e-9);
        assert_eq!(m.angle_at(400_000.0), -30.0);
        // Slow start: less than a linear move after the first 50 ms.
        assert!(m.angle_at(50_000.0) > 10.0 - 40.0 * 50.0 / 400.0);
    }

    #[test]
    fn ramps_longer_than_interval_are_shrunk() {
        let m = Motion::by_interval(0.0, 0.0, 10.0, 100_000.0, 100_000.0, 300_000.0);
        assert_eq!(m.duration_us(), 100_000.0);
        assert_eq!(m.angle_at(100_000.0), 10.0);
    }

    #[test]
    fn by_velocity_cruises_and_triangles() {
        // 50° at 100 °/s with 20 ms ramps: 0.5 s + 20 ms.
        let m = Motion::by_velocity(0.0, 0.0, 50.0, 100.0, 20_000.0, 20_000.0);
        assert!((m.duration_us() - 520_000.0).abs() < 1e-6);
        // Cruise speed 100 °/s in the middle.
        let v = (m.angle_at(260_000.0) - m.angle_at(250_000.0)) / 0.01;
        assert!((v - 100.0).abs() < 1e-6, "{v}");
        // 1° at 750 °/s with 100 ms ramps never reaches 750 °/s.
        let m = Motion::by_velocity(0.0, 0.0, 1.0, 750.0, 100_000.0, 100_000.0);
        let k = (1.0f64 / 75.0).sqrt();
        assert!((m.duration_us() - 200_000.0 * k).abs() < 1e-6);
        assert_eq!(m.angle_at(1e9), 1.0);
    }

    #[test]
    fn zero_velocity_holds() {
        let m = Motion::by_velocity(0.0, 5.0, 50.0, 0.0, 0.0, 0.0);
        assert_eq!(m.angle_at(1e12), 5.0);
    }

    proptest! {
        /// Monotone from start to target, within the two, exact at both ends.
        #[test]
        fn profile_is_monotone_and_bounded(
            from in -180.0f64..180.0,
            to in -180.0f64..180.0,
            interval in 0.0f64..3e6,
            acc in 0.0f64..1e6,
            dec in 0.0f64..1e6,
            velocity in prop::option::of(1.0f64..750.0),
        ) {
            let m = match velocity {
                Some(v) => Motion::by_velocity(0.0, from, to, v, acc, dec),
                None => Motion::by_interval(0.0, from, to, interval, acc, dec),
            };
            prop_assert_eq!(m.angle_at(0.0), from);
            prop_assert_eq!(m.angle_at(m.end_us()), to);
            let (lo, hi) = (from.min(to) - 1e-9, from.max(to) + 1e-9);
            let mut last = from;
            for i in 0..=200 {
                let a = m.angle_at(m.end_us() * f64::from(i) / 200.0);
                prop_assert!(a.is_finite() && a >= lo && a <= hi);
                prop_assert!((a - last) * (to - from) >= -1e-9);
                last = a;
            }
        }
    }
}
