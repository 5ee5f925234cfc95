//! (h) The product's own patterns on their figure (issue 25): every lit
//! sample of the spot a `pattern`, `goto` or `grid` run moves lies within
//! [`Spot::tolerance_mm`] (the table of rule (e)) of the figure
//! [`super::pattern_model`] reads from the transcript: the grid points
//! (and in `laser auto` the gimbal's or stepper's travel between
//! consecutive points), or the strokes of a path (in `laser auto`; a path
//! is dark in `laser dwell`), half the gimbal's interpolation step added
//! on a path.

use super::conformance::{OffEpisode, Samples, extend_episode, samples, window};
use super::gcode_model::Spot;
use super::gcode_piece::Piece;
use super::inputs::SafetyInputs;
use super::pattern_model::{JudgedRun, judged_runs};
use super::violation::{Violation, ViolationKind};

/// Lit samples closer together than this belong to one reported
/// episode, µs.
const EPISODE_GAP_US: u64 = 100_000;

/// (h) on every judged run of the recording.
pub(super) fn patterns_on_their_figure(inputs: &SafetyInputs<'_>) -> Vec<Violation> {
    let (pointing, galvo) = samples(inputs);
    let mut found = Vec::new();
    for run in judged_runs(inputs.transcript, inputs.events) {
        let of: &Samples = if run.spot == Spot::Galvo {
            &galvo
        } else {
            &pointing
        };
        let end = run.end_us.min(inputs.end_us);
        found.extend(off_figure(&run, window(of, run.start_us, end)));
    }
    found
}

/// The nearest piece to `p` and its distance, mm, looking near `hint`
/// first (the spot goes along the figure).
fn nearest(pieces: &[Piece], p: [f64; 2], hint: usize, tol: f64) -> Option<(usize, f64)> {
    let near = |k: usize| (k, pieces[k].distance_mm(p));
    let lo = hint.saturating_sub(2);
    let hi = (hint + 8).min(pieces.len());
    (lo..hi).map(near).find(|n| n.1 <= tol).or_else(|| {
        (0..pieces.len())
            .map(near)
            .min_by(|a, b| a.1.total_cmp(&b.1))
    })
}

/// Lit samples of one run farther than the tolerance from its figure, as
/// episodes.
fn off_figure(run: &JudgedRun, samples: &[(u64, [f64; 2], bool)]) -> Vec<Violation> {
    let tol = run.spot.tolerance_mm() + run.extra_mm;
    let mut found = Vec::new();
    // (first µs, last µs, samples, worst mm, where).
    let mut episode: Option<OffEpisode> = None;
    let mut hint = 0usize;
    for &(t, p, _) in samples.iter().filter(|s| s.2) {
        let d = match nearest(&run.pieces, p, hint, tol) {
            Some((k, d)) if d <= tol => {
                hint = k;
                continue;
            }
            Some((_, d)) => d,
            None => f64::INFINITY,
        };
        if let Some(done) = extend_episode(&mut episode, (t, d, p), EPISODE_GAP_US) {
            found.extend(report(run, Some(done), tol));
        }
    }
    found.extend(report(run, episode, tol));
    found
}

fn report(run: &JudgedRun, episode: Option<OffEpisode>, tol: f64) -> Option<Violation> {
    let (first, last, n, worst, p) = episode?;
    let what = if run.pieces.is_empty() {
        "lit where its laser mode draws nothing".to_owned()
    } else {
        format!("worst {worst:.2} mm off (tolerance {tol:.2} mm)")
    };
    Some(Violation {
        kind: ViolationKind::OffFigure,
        t_us: first,
        detail: format!(
            "{:?} spot lit off the figure of `{}`: {n} samples until {:.3} ms, {what} at ({:.2}, {:.2}) mm",
            run.spot,
            run.line,
            last as f64 / 1000.0,
            p[0],
            p[1]
        ),
    })
}

#[cfg(test)]
mod tests;
