//! The laser output on PB0 with a power level (issue 12: G-code's S).
//!
//! PB0 is TIM3_CH3 on alternate function 2 (STM32F407 datasheet, table
//! 9). Three states, chosen by the pin's mode (GPIOB MODER):
//!
//! | level          | PB0 mode                      | output |
//! |----------------|-------------------------------|--------|
//! | dark (0)       | GPIO output, ODR low          | low    |
//! | 1–999 ‰        | AF2: TIM3_CH3, PWM mode 1     | duty = level |
//! | full (1000 ‰)  | GPIO output, ODR high         | high   |
//!
//! Dark is a GPIO output so that the galvo's laser stream (DMA writes to
//! GPIOB BSRR, on/off per sample) keeps driving PB0 as before: the
//! sequencer's laser is dark whenever the galvo draws.
//!
//! PWM at [`LASER_PWM_HZ`] = 1 kHz, grbl's laser PWM frequency, so laser
//! modules set up for grbl controllers see the signal they expect; TIM3
//! counts at 84 MHz / 2, 42 000 counts a period (> 15 bits of duty). At
//! 3 000 mm/min the spot moves 0.05 mm per period, a tenth of the servo
//! resolution: no visible dashing. CCR3 is preloaded (a new level takes
//! effect at the next period, without a glitch).
//!
//! Darkness never waits for a period: [`laser_dark`] (the master gate's
//! close hook, from any context) forces OC3REF low through OC3M =
//! "force inactive" (RM0090 §18.4.7: takes effect at once, OC3M is not
//! preloaded), clears the pin's ODR bit through BSRR and switches PB0 back
//! to a GPIO output. The panic and HardFault paths do the first two with
//! plain stores ([`TIM3_CCMR2`], `crate::panic`): either mode is then low.

use embassy_stm32::Peri;
use embassy_stm32::gpio::Output;
use embassy_stm32::pac;
use embassy_stm32::pac::gpio::vals::Moder;
use embassy_stm32::pac::timer::vals::Ocm;
use embassy_stm32::peripherals::TIM3;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::Channel;
use embassy_stm32::timer::low_level::{RoundTo, Timer};
use laser_app::laser_gate::LaserGate;
use laser_app::sequencer::{LaserPower, LaserSwitch};

/// Bit of the laser-enable pin in GPIOB (PB0).
pub const LASER_PIN_BIT: usize = 0;

/// Laser PWM frequency, Hz (grbl's ≈ 1 kHz).
pub const LASER_PWM_HZ: u32 = 1_000;
/// PB0's alternate function for TIM3_CH3.
const TIM3_AF: u8 = 2;
/// Address of TIM3's CCMR2 (RM0090 §18.4.8; TIM3 at 0x4000_0400, CCMR2 at
/// offset 0x1C), for the HardFault handler's assembly.
pub const TIM3_CCMR2: u32 = 0x4000_041C;
/// CCMR2 with channel 3 an output forced inactive (OC3M = 100, CC3S = 00;
/// channel 4 unused).
pub const CCMR2_FORCE_INACTIVE: u32 = 0b100 << 4;

/// Dark at once, from any context: OC3 forced low, ODR low, PB0 a GPIO
/// output again (for the galvo's laser stream).
pub fn laser_dark() {
    pac::TIM3
        .ccmr_output(1)
        .write(|w| w.set_ocm(0, Ocm::FORCE_INACTIVE));
    pac::GPIOB.bsrr().write(|w| w.set_br(LASER_PIN_BIT, true));
    pin_mode(Moder::OUTPUT);
}

/// Switches PB0's mode (GPIO output or AF2 TIM3_CH3): a read-modify-write
/// of MODER, atomic against the gate hook.
fn pin_mode(mode: Moder) {
    cortex_m::interrupt::free(|_| {
        pac::GPIOB
            .moder()
            .modify(|w| w.set_moder(LASER_PIN_BIT, mode));
    });
}

/// The laser output (PB0, active high) with its power level, ANDed with
/// the master laser gate: lit only while the gate is open, and the gate's
/// close hook ([`crate::board::laser_gate_changed`]) darkens it at once
/// from whatever context closed it.
pub struct LaserPin {
    /// PB0, created low (its mode is switched between output and AF2).
    _pin: Output<'static>,
    /// TIM3, running at [`LASER_PWM_HZ`], channel 3 forced inactive.
    timer: Timer<'static, TIM3>,
    /// Counts per PWM period (ARR + 1).
    period: u32,
    /// The master gate.
    gate: &'static LaserGate,
}

impl LaserPin {
    /// The output, dark: `pin` (PB0, created low) and TIM3 set up for PWM
    /// on channel 3, which stays forced inactive until a level is set.
    pub fn new(pin: Output<'static>, tim3: Peri<'static, TIM3>, gate: &'static LaserGate) -> Self {
        let timer = Timer::new(tim3);
        timer.set_frequency(Hertz(LASER_PWM_HZ), RoundTo::Faster);
        timer.set_autoreload_preload(true);
        let period = u32::from(timer.get_max_compare_value()) + 1;
        pac::TIM3
            .ccmr_output(1)
            .write(|w| w.set_ocm(0, Ocm::FORCE_INACTIVE));
        timer.enable_channel(Channel::Ch3, true);
        timer.generate_update_event();
        timer.start();
        cortex_m::interrupt::free(|_| {
            pac::GPIOB
                .afr(0)
                .modify(|w| w.set_afr(LASER_PIN_BIT, TIM3_AF));
        });
        defmt::assert!(pac::TIM3.ccmr_output(1).as_ptr() as u32 == TIM3_CCMR2);
        Self {
            _pin: pin,
            timer,
            period,
            gate,
        }
    }
}

impl LaserSwitch for LaserPin {
    fn set(&mut self, power: LaserPower) {
        if !power.is_on() || !self.gate.is_open() {
            return laser_dark();
        }
        if power == LaserPower::FULL {
            pac::GPIOB.bsrr().write(|w| w.set_bs(LASER_PIN_BIT, true));
            pin_mode(Moder::OUTPUT);
        } else {
            let compare = power.scaled(self.period).max(1);
            self.timer.set_compare_value(Channel::Ch3, compare as u16);
            pac::TIM3.ccmr_output(1).write(|w| {
                w.set_ocm(0, Ocm::PWM_MODE1);
                w.set_ocpe(0, true);
            });
            pin_mode(Moder::ALTERNATE);
        }
        // A close between the check and the writes has already run its
        // hook: look again so the output cannot stay lit.
        if !self.gate.is_open() {
            laser_dark();
        }
    }
}
