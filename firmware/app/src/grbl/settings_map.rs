//! grbl's `$N` settings (grbl's `doc/markdown/settings.md`, 1.1 numbering)
//! and how this controller answers each: [`Binding::Product`] ones are the
//! wiring's to connect to a product parameter (read by `$$`, written by
//! `$N=`); [`Binding::Fixed`] ones are answered with their fixed value,
//! which is what this machine does (e.g. no limit switches, laser mode on).
//! The product's settings have no stable numeric ids yet, so the product
//! side is named in words.

/// Where a setting's value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Binding {
    /// A product parameter (named here) or protocol state the wiring keeps.
    Product(&'static str),
    /// A fixed value describing this machine.
    Fixed,
}

/// One grbl setting.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GrblSetting {
    /// grbl's number (`$N`).
    pub number: u16,
    /// grbl's name for it.
    pub name: &'static str,
    /// Unit as grbl states it.
    pub unit: &'static str,
    /// Decimals grbl prints in `$$` (0 = integer).
    pub decimals: u8,
    /// Value before any `$N=` (the fixed value for [`Binding::Fixed`]).
    pub default: f64,
    /// Where the value comes from.
    pub binding: Binding,
}

const fn fixed(
    number: u16,
    name: &'static str,
    unit: &'static str,
    decimals: u8,
    default: f64,
) -> GrblSetting {
    GrblSetting {
        number,
        name,
        unit,
        decimals,
        default,
        binding: Binding::Fixed,
    }
}

const fn product(
    number: u16,
    name: &'static str,
    unit: &'static str,
    decimals: u8,
    default: f64,
    parameter: &'static str,
) -> GrblSetting {
    GrblSetting {
        number,
        name,
        unit,
        decimals,
        default,
        binding: Binding::Product(parameter),
    }
}

/// Every setting `$$` lists, in grbl's order.
pub const SETTINGS: &[GrblSetting] = &[
    fixed(0, "Step pulse time", "microseconds", 0, 10.0),
    fixed(1, "Step idle delay", "milliseconds", 0, 255.0),
    fixed(2, "Step pulse invert", "mask", 0, 0.0),
    fixed(3, "Step direction invert", "mask", 0, 0.0),
    fixed(4, "Invert step enable pin", "boolean", 0, 0.0),
    fixed(5, "Invert limit pins", "boolean", 0, 0.0),
    fixed(6, "Invert probe pin", "boolean", 0, 0.0),
    product(
        10,
        "Status report options",
        "mask",
        0,
        1.0,
        "console: status report mask (MPos, Bf:)",
    ),
    product(
        11,
        "Junction deviation",
        "millimeters",
        3,
        0.010,
        "gcode.junction_mm (saved)",
    ),
    product(
        12,
        "Arc tolerance",
        "millimeters",
        3,
        0.002,
        "arc chord tolerance",
    ),
    fixed(13, "Report in inches", "boolean", 0, 0.0),
    fixed(20, "Soft limits enable", "boolean", 0, 1.0),
    fixed(21, "Hard limits enable", "boolean", 0, 0.0),
    fixed(22, "Homing cycle enable", "boolean", 0, 1.0),
    fixed(23, "Homing direction invert", "mask", 0, 0.0),
    fixed(24, "Homing locate feed rate", "mm/min", 3, 25.0),
    fixed(25, "Homing search seek rate", "mm/min", 3, 500.0),
    fixed(26, "Homing switch debounce delay", "milliseconds", 0, 250.0),
    fixed(27, "Homing switch pull-off distance", "millimeters", 3, 1.0),
    product(
        30,
        "Maximum spindle speed",
        "RPM",
        0,
        1000.0,
        "laser power S for full power",
    ),
    product(
        31,
        "Minimum spindle speed",
        "RPM",
        0,
        0.0,
        "laser power S for the lowest power",
    ),
    product(
        32,
        "Laser-mode enable",
        "boolean",
        0,
        1.0,
        "laser mode (G0 dark, M4 dynamic power)",
    ),
    fixed(100, "X-axis travel resolution", "step/mm", 3, 100.0),
    fixed(101, "Y-axis travel resolution", "step/mm", 3, 100.0),
    fixed(102, "Z-axis travel resolution", "step/mm", 3, 100.0),
    product(
        110,
        "X-axis maximum rate",
        "mm/min",
        3,
        60_000.0,
        "gimbal/galvo maximum spot speed on X",
    ),
    product(
        111,
        "Y-axis maximum rate",
        "mm/min",
        3,
        60_000.0,
        "gimbal/galvo maximum spot speed on Y",
    ),
    fixed(112, "Z-axis maximum rate", "mm/min", 3, 500.0),
    product(
        120,
        "X-axis acceleration",
        "mm/sec^2",
        3,
        2000.0,
        "spot acceleration limit on X",
    ),
    product(
        121,
        "Y-axis acceleration",
        "mm/sec^2",
        3,
        2000.0,
        "spot acceleration limit on Y",
    ),
    fixed(122, "Z-axis acceleration", "mm/sec^2", 3, 10.0),
    product(
        130,
        "X-axis maximum travel",
        "millimeters",
        3,
        400.0,
        "board width",
    ),
    product(
        131,
        "Y-axis maximum travel",
        "millimeters",
        3,
        300.0,
        "board height",
    ),
    fixed(132, "Z-axis maximum travel", "millimeters", 3, 0.0),
];

/// The setting numbered `number`, if grbl 1.1 has it.
pub fn find(number: u16) -> Option<&'static GrblSetting> {
    SETTINGS.iter().find(|s| s.number == number)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_sorted_unique_and_names_the_issue_mappings() {
        assert!(SETTINGS.windows(2).all(|w| w[0].number < w[1].number));
        for n in [30, 31, 32, 110, 111, 120, 121, 130, 131, 10] {
            assert!(
                matches!(find(n).map(|s| s.binding), Some(Binding::Product(_))),
                "${n}"
            );
        }
        assert_eq!(find(32).map(|s| s.default), Some(1.0), "laser mode on");
        assert_eq!(find(7), None);
        assert!(SETTINGS.iter().all(|s| s.default >= 0.0 && s.decimals <= 3));
    }
}
