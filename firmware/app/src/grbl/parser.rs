//! G-code lines → [`Block`]s, with grbl 1.1's semantics and error checks
//! for the laser subset (G0–G3, G4, G10 L2/L20, G17, G20/G21, G53, G54,
//! G80, G90/G91, G91.1, G92/G92.1, G93/G94, M0–M2, M3–M5, M7–M9, M30, F,
//! S, N, T; Z accepted and ignored).
//!
//! Why hand-written: the `gcode` crate (0.7, maintained, `no_std` core with
//! a visitor API) was evaluated. It models syntax only — arguments grouped
//! under the preceding G/M command — so grbl's flat per-block word rules
//! (modal groups, repeated and unused words, axis-command conflicts) would
//! still have to be written on top, its diagnostics do not map onto grbl's
//! error numbers, and it reads numbers with `core`'s `str::parse::<f32>`,
//! linking the float-parsing code this firmware keeps out (README, "Keeping
//! the image small"), at f32 precision. grbl's lexical rules fit in
//! [`super::words`] (~100 lines), so no crate is used. (`async-gcode` 0.3
//! is stream/async oriented, std by default, and has the same mismatch.)
//! Measured flash cost of `gcode` 0.7.0 (`default-features = false`, its
//! zero-allocation `core::parse` with a visitor folding every word) in a
//! throwaway `#![no_std]` thumbv7em-none-eabihf binary, `opt-level = "z"`,
//! LTO, one codegen unit: +20 962 B over the same binary folding the
//! line's bytes (text +8 892 B, rodata +12 072 B), of which 14 954 B are
//! `core`'s f32 parsing (`dec2flt`, its 10.4 KB power-of-five table) that
//! this firmware does not link otherwise — 8 % of the then 256 KiB budget for
//! the lexical layer alone, before grbl's semantics.
//! Flash cost of this module (parser, jog, `$` commands, every report and
//! the settings table) measured in a thumbv7em `opt-level = "z"` LTO build:
//! ~10 KB of its own code, plus `core::fmt`, `ryu`, `libm` and soft-f64
//! routines the firmware already links.

use super::block::{Arc, Block, Blocks, Laser, PointMm, SpindleMode, clamped_feed_mm_min};
use super::collect::{self, AXES, Collected, CoolantWord, NonModal, ProgramFlow};
use super::collect::{F, I, J, K, L, N, P, R, S, T, X, Y};
use super::error::GrblError;
use super::state::{Distance, FeedMode, MotionMode, ParserState};

/// Largest |coordinate| accepted anywhere (targets, centres, offsets), mm;
/// beyond it a line is refused with [`GrblError::InvalidTarget`], so all
/// arithmetic stays finite. Far beyond any board.
pub const COORDINATE_LIMIT_MM: f64 = 1e9;

/// grbl's arc end check: the end may be off the start circle by this much
/// without further test, mm…
const ARC_RADIUS_SLACK_MM: f64 = 0.005;
/// …never by more than this, mm…
const ARC_RADIUS_MAX_ERROR_MM: f64 = 0.5;
/// …and otherwise by at most this fraction of the radius.
const ARC_RADIUS_MAX_ERROR_FRACTION: f64 = 0.001;

impl ParserState {
    /// Runs one G-code line: on success the state has advanced and the
    /// blocks to queue are returned; on error nothing changed.
    pub fn execute(&mut self, line: &str) -> Result<Blocks, GrblError> {
        let words = collect::collect(line)?;
        let mut next = *self;
        let blocks = next.apply(&words)?;
        *self = next;
        Ok(blocks)
    }

    /// Parses the G-code of a `$J=` jog (the text after `=`): only G20/G21,
    /// G90/G91, G53, X/Y/Z, F and N are allowed and F is required; the
    /// modes given apply to this jog only. Returns a [`Block::Jog`] (`None`
    /// when the jog ends where it starts); as in grbl, the parser position
    /// becomes the jog target (after a jog cancel the caller sets
    /// [`ParserState::position`] to where the spot stopped). On error
    /// nothing changes.
    pub fn jog(&mut self, text: &str) -> Result<Option<Block>, GrblError> {
        let words = collect::collect(text)?;
        // G53 (group 0), G90/G91 (3), G20/G21 (6); no M words.
        let only_allowed = words.only_groups(1 << 0 | 1 << 3 | 1 << 6)
            && matches!(words.non_modal, None | Some(NonModal::MachineCoordinates))
            && words.present & !(AXES | F | N) == 0;
        if !only_allowed || words.present & AXES == 0 {
            return Err(GrblError::InvalidJogCommand);
        }
        let scale = words.units.unwrap_or(self.units).mm_per_unit();
        let feed = words.value(F).ok_or(GrblError::UndefinedFeedRate)? * scale;
        if feed <= 0.0 {
            return Err(GrblError::UndefinedFeedRate);
        }
        let mut probe = *self;
        probe.distance = words.distance.unwrap_or(self.distance);
        probe.units = words.units.unwrap_or(self.units);
        let machine = words.non_modal == Some(NonModal::MachineCoordinates);
        let to = probe.target(&words, machine)?;
        let from = core::mem::replace(&mut self.position, to);
        Ok((to != from).then_some(Block::Jog {
            from,
            to,
            feed_mm_min: clamped_feed_mm_min(feed),
        }))
    }

    /// The modal and value effects of one collected line, in grbl's order.
    fn apply(&mut self, words: &Collected) -> Result<Blocks, GrblError> {
        let mut blocks = Blocks::new();
        let mut used = N | F | S | T;
        let block_feed = self.apply_modes(words);
        if words.non_modal == Some(NonModal::Dwell) {
            let seconds = words.value(P).ok_or(GrblError::ValueWordMissing)?;
            used |= P;
            // grbl's laser mode lights a dwell only in G1/G2/G3 state.
            let feed_state = !matches!(self.motion, MotionMode::Rapid | MotionMode::Cancel);
            let laser = if feed_state {
                self.laser()
            } else {
                Laser {
                    mode: SpindleMode::Off,
                    power: self.power,
                }
            };
            push(&mut blocks, Block::Dwell { seconds, laser });
        }
        let has_axes = words.present & AXES != 0;
        let motion_command = words.motion.is_some_and(|m| m != MotionMode::Cancel);
        let offset_command = matches!(
            words.non_modal,
            Some(NonModal::SetCoordinateData | NonModal::SetOffset)
        );
        if motion_command && offset_command {
            return Err(GrblError::AxisCommandConflict);
        }
        let machine = words.non_modal == Some(NonModal::MachineCoordinates);
        if machine && !matches!(self.motion, MotionMode::Rapid | MotionMode::Linear) {
            return Err(GrblError::G53InvalidMotionMode);
        }
        match words.non_modal {
            Some(NonModal::SetCoordinateData) => {
                self.set_coordinate_data(words)?;
                used |= AXES | L | P;
            }
            Some(NonModal::SetOffset) => {
                if !has_axes {
                    return Err(GrblError::NoAxisWords);
                }
                let scale = self.units.mm_per_unit();
                let axis = |bit, position: f64, g54: f64, old: f64| match words.value(bit) {
                    Some(v) => position - g54 - v * scale,
                    None => old,
                };
                self.g92 = PointMm {
                    x_mm: axis(X, self.position.x_mm, self.g54.x_mm, self.g92.x_mm),
                    y_mm: axis(Y, self.position.y_mm, self.g54.y_mm, self.g92.y_mm),
                };
                check_point(self.g92)?;
                used |= AXES;
            }
            Some(NonModal::ClearOffset) => self.g92 = PointMm::ZERO,
            _ => {}
        }
        if !offset_command && (has_axes || motion_command) {
            used |= self.motion_block(words, machine, block_feed, &mut blocks)?;
        }
        if words.present & !used != 0 {
            return Err(GrblError::UnusedWords);
        }
        match words.program {
            Some(ProgramFlow::Pause) => push(&mut blocks, Block::Pause),
            Some(ProgramFlow::End) => {
                self.end_program();
                push(&mut blocks, Block::End);
            }
            Some(ProgramFlow::OptionalStop) | None => {}
        }
        Ok(blocks)
    }

    /// Modal groups, N, F, S, T, M3–M5 and M7–M9 (they cannot fail);
    /// returns this block's feed (see [`Self::block_feed`]).
    fn apply_modes(&mut self, words: &Collected) -> f64 {
        let previous_feed_mode = self.feed_mode;
        self.feed_mode = words.feed_mode.unwrap_or(self.feed_mode);
        self.units = words.units.unwrap_or(self.units);
        self.distance = words.distance.unwrap_or(self.distance);
        self.motion = words.motion.unwrap_or(self.motion);
        // grbl: a line without N reports line number 0.
        self.line_number = words.value(N).map_or(0, |n| n as u32);
        if let Some(s) = words.value(S) {
            self.power = s;
        }
        if let Some(t) = words.value(T) {
            self.tool = t as u8;
        }
        self.spindle = words.spindle.unwrap_or(self.spindle);
        match words.coolant {
            Some(CoolantWord::Mist) => self.coolant.mist = true,
            Some(CoolantWord::Flood) => self.coolant.flood = true,
            Some(CoolantWord::Off) => self.coolant = Default::default(),
            None => {}
        }
        self.block_feed(words, previous_feed_mode)
    }

    /// This block's feed, mm/min (G94) or 1/min (G93), and the new modal F.
    fn block_feed(&mut self, words: &Collected, previous: FeedMode) -> f64 {
        match (self.feed_mode, words.value(F)) {
            (FeedMode::InverseTime, f) => f.unwrap_or(0.0),
            (FeedMode::UnitsPerMinute, Some(f)) => {
                self.feed_mm_min = f * self.units.mm_per_unit();
                self.feed_mm_min
            }
            // Leaving G93 without a new F leaves the feed undefined.
            (FeedMode::UnitsPerMinute, None) if previous == FeedMode::InverseTime => {
                self.feed_mm_min = 0.0;
                0.0
            }
            (FeedMode::UnitsPerMinute, None) => self.feed_mm_min,
        }
    }

    /// G10 L2 (origin = values) / L20 (origin such that the position reads
    /// as the values), P0 (active system) or P1 (G54).
    fn set_coordinate_data(&mut self, words: &Collected) -> Result<(), GrblError> {
        let (l, p) = match (words.value(L), words.value(P)) {
            (Some(l), Some(p)) => (l, p),
            _ => return Err(GrblError::ValueWordMissing),
        };
        if l != 2.0 && l != 20.0 {
            return Err(GrblError::UnsupportedCommand);
        }
        if p != libm::trunc(p) {
            return Err(GrblError::CommandValueNotInteger);
        }
        if p > 1.0 {
            return Err(GrblError::UnsupportedCoordinateSystem);
        }
        if words.present & AXES == 0 {
            return Err(GrblError::NoAxisWords);
        }
        let scale = self.units.mm_per_unit();
        let axis = |bit, position: f64, g92: f64, old: f64| match words.value(bit) {
            Some(v) if l == 2.0 => v * scale,
            Some(v) => position - g92 - v * scale,
            None => old,
        };
        self.g54 = PointMm {
            x_mm: axis(X, self.position.x_mm, self.g92.x_mm, self.g54.x_mm),
            y_mm: axis(Y, self.position.y_mm, self.g92.y_mm, self.g54.y_mm),
        };
        check_point(self.g54)
    }

    /// The end point of this block's axis words, machine mm.
    fn target(&self, words: &Collected, machine: bool) -> Result<PointMm, GrblError> {
        let scale = self.units.mm_per_unit();
        let offset = self.work_offset();
        let axis = |bit, position: f64, offset: f64| match words.value(bit) {
            None => position,
            Some(v) if machine => v * scale,
            Some(v) if self.distance == Distance::Absolute => v * scale + offset,
            Some(v) => position + v * scale,
        };
        let to = PointMm {
            x_mm: axis(X, self.position.x_mm, offset.x_mm),
            y_mm: axis(Y, self.position.y_mm, offset.y_mm),
        };
        check_point(to)?;
        Ok(to)
    }

    /// The motion of the modal motion mode; returns the words it used.
    fn motion_block(
        &mut self,
        words: &Collected,
        machine: bool,
        block_feed: f64,
        blocks: &mut Blocks,
    ) -> Result<u16, GrblError> {
        let has_axes = words.present & AXES != 0;
        let from = self.position;
        let feed_mode = self.feed_mode;
        let feed = |length_mm: f64| {
            clamped_feed_mm_min(match feed_mode {
                FeedMode::UnitsPerMinute => block_feed,
                FeedMode::InverseTime => block_feed * length_mm,
            })
        };
        match self.motion {
            MotionMode::Cancel if has_axes => Err(GrblError::AxisWordsExist),
            MotionMode::Cancel => Ok(0),
            MotionMode::Rapid => {
                let to = self.target(words, machine)?;
                if to != from {
                    push(blocks, Block::Rapid { from, to });
                }
                self.position = to;
                Ok(AXES)
            }
            _ if block_feed <= 0.0 => Err(GrblError::UndefinedFeedRate),
            MotionMode::Linear => {
                let to = self.target(words, machine)?;
                if to != from {
                    let feed_mm_min = feed(from.distance_to(to));
                    let laser = self.laser();
                    push(
                        blocks,
                        Block::Line {
                            from,
                            to,
                            feed_mm_min,
                            laser,
                        },
                    );
                }
                self.position = to;
                Ok(AXES)
            }
            MotionMode::ArcClockwise | MotionMode::ArcCounterClockwise => {
                if words.present & (X | Y) == 0 {
                    return Err(GrblError::NoAxisWordsInPlane);
                }
                let to = self.target(words, machine)?;
                let clockwise = self.motion == MotionMode::ArcClockwise;
                let (centre, used) = self.arc_centre(words, from, to, clockwise)?;
                let arc = Arc::new(from, to, centre, clockwise);
                if arc.length_mm() > 0.0 {
                    let feed_mm_min = feed(arc.length_mm());
                    let laser = self.laser();
                    push(
                        blocks,
                        Block::Arc {
                            arc,
                            feed_mm_min,
                            laser,
                        },
                    );
                }
                self.position = to;
                Ok(AXES | used)
            }
        }
    }

    /// The arc centre from R or from I/J, with grbl's checks (errors 33,
    /// 34, 35); returns the words used.
    fn arc_centre(
        &self,
        words: &Collected,
        from: PointMm,
        to: PointMm,
        clockwise: bool,
    ) -> Result<(PointMm, u16), GrblError> {
        let scale = self.units.mm_per_unit();
        let (dx, dy) = (to.x_mm - from.x_mm, to.y_mm - from.y_mm);
        if let Some(r) = words.value(R) {
            let r = r * scale;
            if from == to {
                return Err(GrblError::InvalidTarget);
            }
            let h_squared = 4.0 * r * r - dx * dx - dy * dy;
            if h_squared < 0.0 {
                return Err(GrblError::ArcRadiusError);
            }
            // Centre on the perpendicular bisector; grbl's sign rules: the
            // short arc for R > 0, the long one for R < 0.
            let mut h = -libm::sqrt(h_squared) / kinematics_core::numeric::hypot(dx, dy);
            if !clockwise {
                h = -h;
            }
            if r < 0.0 {
                h = -h;
            }
            let centre = PointMm {
                x_mm: from.x_mm + 0.5 * (dx - dy * h),
                y_mm: from.y_mm + 0.5 * (dy + dx * h),
            };
            check_point(centre)?;
            return Ok((centre, R));
        }
        if words.present & (I | J) == 0 {
            return Err(GrblError::NoOffsetsInPlane);
        }
        let i = words.value(I).unwrap_or(0.0) * scale;
        let j = words.value(J).unwrap_or(0.0) * scale;
        let centre = PointMm {
            x_mm: from.x_mm + i,
            y_mm: from.y_mm + j,
        };
        check_point(centre)?;
        let radius_error =
            libm::fabs(centre.distance_to(to) - kinematics_core::numeric::hypot(i, j));
        if radius_error > ARC_RADIUS_SLACK_MM
            && (radius_error > ARC_RADIUS_MAX_ERROR_MM
                || radius_error
                    > ARC_RADIUS_MAX_ERROR_FRACTION * kinematics_core::numeric::hypot(i, j))
        {
            return Err(GrblError::InvalidTarget);
        }
        Ok((centre, I | J | K))
    }
}

fn check_point(p: PointMm) -> Result<(), GrblError> {
    let ok = |v: f64| v.is_finite() && libm::fabs(v) <= COORDINATE_LIMIT_MM;
    if ok(p.x_mm) && ok(p.y_mm) {
        Ok(())
    } else {
        Err(GrblError::InvalidTarget)
    }
}

/// Adds a block; a line yields at most one dwell, one motion and one
/// program-flow block, which is the capacity of [`Blocks`].
fn push(blocks: &mut Blocks, block: Block) {
    let _fits = blocks.push(block);
    debug_assert!(_fits.is_ok());
}

#[cfg(test)]
mod tests;
