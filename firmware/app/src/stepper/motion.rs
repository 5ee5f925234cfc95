//! The stepper task's low-priority work, pure: targets → joint angles →
//! microstep moves → planner → segment prep. Board lines and arcs are cut
//! into pieces whose ends go through the IK and whose insides are
//! straight in steps, enough pieces (a power of two) that the spot stays
//! within [`LINE_TOLERANCE_MM`] of the board curve.

mod curve;
mod cut;
mod fast;
mod history;
mod resume;

use curve::{Curve, PieceCut};

use kinematics_core::frames::BoardPoint;
use kinematics_core::gimbal::JointAngles;
use kinematics_core::stepper::{Planner, Segment, SegmentPrep, SegmentQueue, StepBlock, StepMove};

use super::config::{SEGMENT_S, STEP_TIMER_HZ, StepperConfig};
use super::link::messages::{MoveShape, StepperRefusal};
use kinematics_core::numeric::clamp;

/// Largest distance of the pieces' joint-space insides from the board
/// curve, mm (the steps' own rounding, ≤ half a step per axis, comes on
/// top).
pub const LINE_TOLERANCE_MM: f64 = 0.05;
/// Most pieces one line is cut into.
const MAX_PIECES: u32 = 4096;
/// The step timer's queue of prepared segments.
pub type StepQueue = SegmentQueue<{ super::link::STEP_QUEUE_LEN }>;
/// Look-ahead depth of the planner, blocks.
const PLANNER_LEN: usize = 16;

/// Planner, segment prep and the move being cut.
#[derive(Debug, Clone)]
pub struct StepperMotion {
    config: StepperConfig,
    planner: Planner<PLANNER_LEN>,
    prep: SegmentPrep,
    /// Step position where the queued moves end, `[pan, tilt]`.
    planned: [i32; 2],
    /// Board point of the last target (`None` after a stop: then the
    /// board point of `planned`).
    last_point: Option<BoardPoint>,
    line: Option<PieceCut>,
    /// The move in flight, reported when its last step has run.
    pending: Option<u32>,
    /// One move queued behind the line being cut (G-code blocks arrive
    /// ahead of time), with its request number; it starts when the line
    /// is cut, so the planner joins them at speed.
    next: Option<(u32, Queued)>,
    /// A queued move started being cut (reported as taken).
    started: Option<u32>,
    /// The moves since the last rest, for a hold's resume.
    history: history::History,
    /// Feed override: moves at a feed run at feed × this.
    feed_scale: f64,
    /// A junction deviation (deg) to plan with once the planner is empty.
    junction_pending: Option<f64>,
    /// The joint geometry in single precision, for counting pieces.
    joints32: Option<fast::Joints32>,
}

/// A move waiting behind the line being cut.
#[derive(Debug, Clone, Copy)]
enum Queued {
    Cut(PieceCut),
    Travel([i32; 2]),
}

impl StepperMotion {
    /// At rest at step position 0 with `config`. Not inlined: built in
    /// the task's poll it took ~2.7 KB more of that frame.
    ///
    /// Errors: [`StepperRefusal::BadConfig`].
    #[inline(never)]
    pub fn new(config: StepperConfig) -> Result<Self, StepperRefusal> {
        let (planner, prep) = Self::pipeline(&config)?;
        let joints32 = Self::joints32(&config);
        Ok(Self {
            config,
            planner,
            prep,
            planned: [0; 2],
            last_point: None,
            line: None,
            pending: None,
            next: None,
            started: None,
            history: history::History::default(),
            feed_scale: 1.0,
            junction_pending: None,
            joints32,
        })
    }

    fn pipeline(
        config: &StepperConfig,
    ) -> Result<(Planner<PLANNER_LEN>, SegmentPrep), StepperRefusal> {
        let bad = StepperRefusal::BadConfig;
        config.gimbal.validate().map_err(|_| bad)?;
        let jd_steps = config.junction_deviation_deg / config.deg_per_step();
        let planner = Planner::new(jd_steps).map_err(|_| bad)?;
        let prep = SegmentPrep::new(STEP_TIMER_HZ, SEGMENT_S).map_err(|_| bad)?;
        // The rates must pass the planner's checks.
        kinematics_core::stepper::motion::validate_move(&Self::step_move(config, [1, 0]))
            .map_err(|_| bad)?;
        Ok((planner, prep))
    }

    /// The single-precision joint geometry of `config` (`fast.rs`).
    fn joints32(config: &StepperConfig) -> Option<fast::Joints32> {
        fast::Joints32::of(&config.gimbal, config.min_deg, config.max_deg)
    }

    fn step_move(config: &StepperConfig, steps: [i32; 2]) -> StepMove {
        StepMove {
            steps,
            nominal_rate_steps_per_s: config.max_speed_deg_s / config.deg_per_step(),
            accel_steps_per_s2: config.accel_deg_s2 / config.deg_per_step(),
        }
    }

    /// The parameters in use.
    pub fn config(&self) -> &StepperConfig {
        &self.config
    }

    /// New parameters (at rest only: the position in steps is kept; a new
    /// step angle or zero moves the joint angles it stands for).
    ///
    /// Errors: [`StepperRefusal::BadConfig`] (nothing changes).
    pub fn configure(&mut self, config: StepperConfig) -> Result<(), StepperRefusal> {
        let (planner, prep) = Self::pipeline(&config)?;
        self.joints32 = Self::joints32(&config);
        self.config = config;
        self.planner = planner;
        self.prep = prep;
        self.last_point = None;
        self.junction_pending = None;
        Ok(())
    }

    /// Whether nothing is left to plan or cut (the step timer may still be
    /// running prepared segments).
    pub fn is_planned_out(&self) -> bool {
        self.line.is_none()
            && self.next.is_none()
            && self.history.is_done()
            && self.planner.is_empty()
            && !self.prep.is_busy()
    }

    /// Queues move `seq` to the board point `point` (cm), along the board
    /// line or arc from the previous target when `shape` says so (and
    /// there is one; else as travel), at `feed_mm_s` along the board curve
    /// (`None`: the axes' speed limit). While a line is still being cut, one
    /// move waits behind it; `Ok(false)` says it waits (it is reported by
    /// [`Self::take_started`] when its cutting starts), `Ok(true)` that it
    /// was taken at once.
    ///
    /// Errors: [`StepperRefusal`] (nothing queued; [`StepperRefusal::Busy`]
    /// while a line is cut and a move already waits).
    pub fn move_to(
        &mut self,
        seq: u32,
        point: BoardPoint,
        shape: MoveShape,
        feed_mm_s: Option<f64>,
    ) -> Result<bool, StepperRefusal> {
        let taken = self.queue(seq, point, shape, feed_mm_s)?;
        self.history.push(seq, point, shape, feed_mm_s);
        Ok(taken)
    }

    /// [`Self::move_to`] without remembering it.
    fn queue(
        &mut self,
        seq: u32,
        point: BoardPoint,
        shape: MoveShape,
        feed_mm_s: Option<f64>,
    ) -> Result<bool, StepperRefusal> {
        if self.next.is_some() {
            return Err(StepperRefusal::Busy);
        }
        let end = self.steps_at(point)?;
        self.apply_junction();
        // After power-up, a stop or a halt the line starts where the
        // counted steps are.
        let from = self
            .last_point
            .or_else(|| self.board_point_of(self.planned));
        let queued = match from.and_then(|from| Curve::of(from, point, shape)) {
            Some(curve) => Queued::Cut(PieceCut {
                curve,
                feed_mm_s,
                pieces: self.pieces_for(curve)?,
                next: 1,
            }),
            None if shape == MoveShape::Travel => Queued::Travel(end),
            // Axes off the board (no board point): no line from there.
            None => return Err(StepperRefusal::Unreachable),
        };
        self.last_point = Some(point);
        if self.line.is_some() {
            self.next = Some((seq, queued));
            return Ok(false);
        }
        self.start(queued)?;
        self.pending = Some(seq);
        Ok(true)
    }

    /// Starts cutting (or queues the travel of) a move.
    fn start(&mut self, queued: Queued) -> Result<(), StepperRefusal> {
        match queued {
            Queued::Cut(cut) => {
                self.line = Some(cut);
                Ok(())
            }
            Queued::Travel(end) => {
                self.line = None;
                self.push_to(end, None)
            }
        }
    }

    /// The queued move whose cutting started since the last call.
    pub fn take_started(&mut self) -> Option<u32> {
        self.started.take()
    }

    /// Step positions for a board point, inside the soft limits.
    fn steps_at(&self, point: BoardPoint) -> Result<[i32; 2], StepperRefusal> {
        let j = self.joints_at(point)?;
        self.config.steps_of(j)
    }

    /// The board point the axes aim at from step position `steps`
    /// (`None`: off the board, or beyond the soft limits — e.g. wound by
    /// a failed homing seek — where a line cut from it would first turn
    /// the axes back through the limits).
    pub(super) fn board_point_of(&self, steps: [i32; 2]) -> Option<BoardPoint> {
        let j = self.config.joints_of(steps)?;
        self.config.steps_of(j).ok()?;
        self.config.gimbal.fk(j).ok()
    }

    fn joints_at(&self, point: BoardPoint) -> Result<JointAngles, StepperRefusal> {
        self.config
            .gimbal
            .ik(point)
            .map_err(|_| StepperRefusal::Unreachable)
    }

    /// Queues the move from the planned position to `end` (steps), with
    /// `feed` = (spot speed mm/s, piece length mm) when a feed applies.
    fn push_to(&mut self, end: [i32; 2], feed: Option<(f64, f64)>) -> Result<(), StepperRefusal> {
        let delta = [
            end[0].wrapping_sub(self.planned[0]),
            end[1].wrapping_sub(self.planned[1]),
        ];
        let mut mv = Self::step_move(&self.config, delta);
        let mut feed_rate = 0.0;
        if let Some((speed_mm_s, length_mm)) = feed.filter(|f| f.1 > 0.0) {
            // Step events per mm of the piece, at the feed.
            let events = delta[0].unsigned_abs().max(delta[1].unsigned_abs());
            feed_rate = speed_mm_s * f64::from(events) / length_mm;
            mv.nominal_rate_steps_per_s = clamp(
                feed_rate * self.feed_scale,
                kinematics_core::stepper::motion::MIN_RATE_STEPS_PER_S,
                mv.nominal_rate_steps_per_s,
            );
        }
        self.planner
            .push_feed(&mv, feed_rate)
            .map_err(|_| StepperRefusal::BadConfig)?;
        self.planned = end;
        Ok(())
    }

    /// Queues the line's next pieces while the planner has room.
    fn feed_line(&mut self) {
        while let Some(mut cut) = self.line {
            if self.planner.len() >= PLANNER_LEN || cut.next > cut.pieces {
                break;
            }
            // Checked in `pieces_for`: reachable and inside the limits.
            let (a, b) = (cut.point(cut.next - 1), cut.point(cut.next));
            let Ok(end) = self.steps_at(b) else {
                self.line = None;
                break;
            };
            let length_mm = crate::domain::units::mm_from_cm(kinematics_core::numeric::hypot(
                b.x_cm - a.x_cm,
                b.y_cm - a.y_cm,
            ));
            if self
                .push_to(end, cut.feed_mm_s.map(|f| (f, length_mm)))
                .is_err()
            {
                self.line = None;
                break;
            }
            cut.next += 1;
            self.line = (cut.next <= cut.pieces).then_some(cut);
        }
    }

    /// The next segment to prepare (`None`: nothing more for now).
    pub fn next_segment(&mut self) -> Option<Segment> {
        self.feed_line();
        let room = self.line.is_none() && self.planner.len() < PLANNER_LEN;
        if let Some((seq, queued)) = self.next.take_if(|_| room) {
            // Checked when it was queued; a refusal now drops it.
            if self.start(queued).is_ok() {
                self.pending = Some(seq);
                self.started = Some(seq);
            }
            self.feed_line();
        }
        self.queue_again();
        self.prep.next_segment(&mut self.planner)
    }

    /// Decelerates to rest at the limit along the path from where the
    /// step generator is (`queue`, `executing`: see [`Self::hold`]); what
    /// is left of the move is dropped.
    pub fn stop(&mut self, queue: &mut StepQueue, executing: (StepBlock, Option<u32>)) {
        self.hold(queue, executing);
        self.history.rest(None);
    }

    /// A feed hold: as [`Self::stop`], but the moves since the last rest
    /// are kept for [`Self::resume`]. The segments prepared in the step
    /// `queue` are taken back and the braking starts where the segment
    /// the generator runs ends (`executing`: its block and period, from
    /// [`kinematics_core::stepper::StepGenerator::executing`]).
    pub fn hold(&mut self, queue: &mut StepQueue, executing: (StepBlock, Option<u32>)) {
        self.line = None;
        self.next = None;
        self.pending = None;
        self.prep.hold_now(&mut self.planner, executing, queue);
    }

    /// The steps were halted (or a stop came to rest) at `position`:
    /// forget the plan, continue from there.
    pub fn rest_at(&mut self, position: [i32; 2]) {
        self.line = None;
        self.next = None;
        self.pending = None;
        self.planner.clear();
        self.prep.reset();
        self.planned = position;
        self.last_point = None;
    }

    /// The move whose last step has run, once the step timer is idle
    /// (`idle`) and nothing is left to plan.
    pub fn take_arrived(&mut self, idle: bool) -> Option<u32> {
        if idle && self.is_planned_out() {
            let seq = self.pending.take();
            if seq.is_some() {
                self.history.rest(self.last_point);
            }
            seq
        } else {
            None
        }
    }

    /// Queues a move by `delta` microsteps at `speed_deg_s` (homing).
    ///
    /// Errors: [`StepperRefusal::BadConfig`] (the rate is refused).
    pub fn jog(&mut self, delta: [i32; 2], speed_deg_s: f64) -> Result<(), StepperRefusal> {
        let mut mv = Self::step_move(&self.config, delta);
        mv.nominal_rate_steps_per_s = speed_deg_s / self.config.deg_per_step();
        self.planner
            .push(&mv)
            .map_err(|_| StepperRefusal::BadConfig)?;
        self.planned = [
            self.planned[0].wrapping_add(delta[0]),
            self.planned[1].wrapping_add(delta[1]),
        ];
        self.last_point = None;
        Ok(())
    }

    /// G-code's feed override, % (10–200; others ignored): the queued
    /// moves at a feed and the one being cut change speed now.
    pub fn set_feed_percent(&mut self, percent: u8) {
        if !(10..=200).contains(&percent) {
            return;
        }
        self.feed_scale = f64::from(percent) / 100.0;
        let max_rate = Self::step_move(&self.config, [1, 0]).nominal_rate_steps_per_s;
        self.prep
            .set_feed_scale(self.feed_scale, max_rate, &mut self.planner);
    }

    /// The junction deviation from now on, degrees of joint travel (in
    /// use once the planner is next empty; refused values are ignored).
    pub fn set_junction_deg(&mut self, deg: f64) {
        if deg.is_finite() && deg >= 0.0 && deg != self.config.junction_deviation_deg {
            self.junction_pending = Some(deg);
            self.apply_junction();
        }
    }

    /// Plans with the pending junction deviation when nothing is queued.
    fn apply_junction(&mut self) {
        let Some(deg) = self.junction_pending else {
            return;
        };
        if !self.planner.is_empty() || self.prep.is_busy() {
            return;
        }
        if let Ok(planner) = Planner::new(deg / self.config.deg_per_step()) {
            self.planner = planner;
            self.config.junction_deviation_deg = deg;
        }
        self.junction_pending = None;
    }

    /// Step position where the queued moves end.
    pub fn planned_steps(&self) -> [i32; 2] {
        self.planned
    }
}
