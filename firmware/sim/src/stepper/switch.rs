//! A limit switch on a simulated stepper axis: closes when the joint
//! angle of the axis's counted steps (through the true geometry) reaches
//! its position going its way, opens again only `hysteresis_deg` back
//! (a mechanical switch's differential travel).

/// One axis's limit switch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimitSwitch {
    /// Joint angle where it closes, degrees.
    pub closes_at_deg: f64,
    /// It sits beyond `closes_at_deg` in the positive joint direction
    /// (else the negative).
    pub towards_positive: bool,
    /// How far back it opens again, degrees (≥ 0).
    pub hysteresis_deg: f64,
}

impl LimitSwitch {
    /// Whether it is closed at joint angle `angle_deg`, having been
    /// `closed` before.
    pub fn closed_at(&self, angle_deg: f64, closed: bool) -> bool {
        let sign = if self.towards_positive { 1.0 } else { -1.0 };
        // Distance past the closing point, in the switch's direction.
        let past = sign * (angle_deg - self.closes_at_deg);
        if closed {
            past > -self.hysteresis_deg
        } else {
            past >= 0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closes_at_its_angle_and_opens_after_the_hysteresis() {
        let s = LimitSwitch {
            closes_at_deg: 10.0,
            towards_positive: true,
            hysteresis_deg: 0.5,
        };
        assert!(!s.closed_at(9.99, false));
        assert!(s.closed_at(10.0, false));
        assert!(s.closed_at(9.6, true), "within the hysteresis");
        assert!(!s.closed_at(9.5, true));
        let n = LimitSwitch {
            towards_positive: false,
            ..s
        };
        assert!(n.closed_at(9.0, false) && !n.closed_at(10.1, false));
        assert!(n.closed_at(10.4, true) && !n.closed_at(10.5, true));
    }
}
