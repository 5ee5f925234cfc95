//! Building the loop: by value on a host ([`GalvoLoop::new`]), for a
//! board's DAC ([`GalvoLoop::for_dac`]), or in place in its memory
//! ([`GalvoLoop::start_in`]).

use galvo_planner::XyIntegrator;
use kinematics_core::SampleMap;

use super::planning::Planning;
use super::ring::StepRing;
use super::state::{JumpCodes, Motion, Trace};
use super::{GalvoConfig, GalvoError, GalvoLoop};
use crate::galvo::cost::LoopWork;
use crate::galvo::dac::{DacSample, DacStream};

pub(super) fn samples_for(us: u32, ts_s: f64) -> u32 {
    // Whole samples, rounded up: a delay is never shorter than asked.
    libm::ceil(f64::from(us) * 1e-6 / ts_s - 1e-9).max(0.0) as u32
}

impl GalvoLoop {
    /// A loop holding the mirrors at the centre, laser off.
    ///
    /// Errors: [`GalvoError::Planner`] for an invalid mirror model or
    /// sample period, [`GalvoError::Kinematics`] for invalid geometry.
    ///
    /// It plans jumps with every method, in `f64` where the method needs
    /// it (a host); a board's loop is built by [`Self::for_dac`].
    pub fn new(config: GalvoConfig) -> Result<Self, GalvoError> {
        Self::with_planning(config, Planning::HOST)
    }

    /// [`Self::new`] for the loop that feeds `D`, planning jumps as its
    /// board can ([`DacStream::F64_PLANNING`]); also
    /// [`GalvoError::SeedTooSlow`] for `planner seed` where it cannot.
    pub fn for_dac<D: DacStream>(config: GalvoConfig) -> Result<Self, GalvoError> {
        let planning = Planning::of::<D>();
        planning.check(config.method)?;
        Self::with_planning(config, planning)
    }

    /// [`Self::for_dac`] into `slot` (replacing what it held), out of
    /// line and in place: the loop (22 KB) is written into `slot`, its
    /// integrator reset there, never built on the stack and moved. `Err`
    /// leaves `slot` empty.
    #[inline(never)]
    pub fn start_in<D: DacStream>(
        slot: &mut Option<Self>,
        config: GalvoConfig,
    ) -> Result<&mut Self, GalvoError> {
        *slot = None;
        let planning = Planning::of::<D>();
        planning.check(config.method)?;
        let galvo = Self::placed(slot, config, planning)?;
        let disc = galvo.disc;
        let mirrors = galvo.mirrors.reset(&disc, &disc, galvo.active_end_rad);
        if mirrors.is_err() {
            *slot = None;
            return Err(GalvoError::Planner);
        }
        slot.as_mut().ok_or(GalvoError::Planner)
    }

    fn with_planning(config: GalvoConfig, planning: Planning) -> Result<Self, GalvoError> {
        let mut slot = None;
        Self::placed(&mut slot, config, planning)?;
        let galvo = slot.as_mut().ok_or(GalvoError::Planner)?;
        let disc = galvo.disc;
        galvo
            .mirrors
            .reset(&disc, &disc, galvo.active_end_rad)
            .map_err(|_| GalvoError::Planner)?;
        slot.ok_or(GalvoError::Planner)
    }

    /// The loop at the centre written into `slot`, its integrator
    /// [`XyIntegrator::IDLE`] (the caller resets it to `disc`).
    fn placed(
        slot: &mut Option<Self>,
        config: GalvoConfig,
        planning: Planning,
    ) -> Result<&mut Self, GalvoError> {
        let angles_rad = [0.0, 0.0];
        let disc = config
            .mirrors
            .model()
            .and_then(|m| m.discretize(config.sample_period_s))
            .map_err(|_| GalvoError::Planner)?;
        let [x_rad, y_rad] = angles_rad;
        let sample_map = SampleMap::new(&config.galvo).map_err(|_| GalvoError::Kinematics)?;
        let codes = sample_map
            .angles_to_codes(x_rad as f32, y_rad as f32)
            .ok_or(GalvoError::Kinematics)?;
        let ts = config.sample_period_s;
        Ok(slot.insert(Self {
            sample_map,
            planning: config.galvo.cast(),
            disc,
            mirrors: XyIntegrator::IDLE,
            steps: StepRing::new(),
            running: false,
            jump_codes: JumpCodes::EMPTY,
            jump_cursor: None,
            active_end_rad: angles_rad,
            unprepared_samples: 0,
            work: LoopWork::default(),
            motion: Motion::default(),
            queue: heapless::Deque::new(),
            active: None,
            last: DacSample {
                x_code: codes.x.code,
                y_code: codes.y.code,
                laser: false,
            },
            faulted: false,
            pending_config: None,
            on_delay_samples: samples_for(config.laser_on_delay_us, ts),
            off_delay_samples: samples_for(config.laser_off_delay_us, ts),
            jump_planning: planning,
            joining: None,
            trace: Trace::default(),
            config,
        }))
    }
}
