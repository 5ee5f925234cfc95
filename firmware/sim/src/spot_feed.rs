//! The spot feed: where the pointing actuator's spot really is and whether
//! the laser is lit, written to a file for a program outside the simulator
//! (the virtual camera of `cargo xtask calib camera --camera sim`), as a
//! camera on a real bench sees the spot where it really lands.
//!
//! The file holds one line, replaced atomically (written beside it, then
//! renamed) whenever it changes: `<x_mm> <y_mm> <lit>` (board mm, `lit`
//! 1 or 0), or `off-board <lit>` while the beam misses the board.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use embassy_time::Timer;
use laser_app::domain::units::mm_from_cm;

use crate::recorder::Recording;
use crate::spot::SpotFn;

/// Where the spot is, as the feed tells it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeedSample {
    /// The spot on the board, mm (`None`: the beam misses the board).
    pub spot_mm: Option<[f64; 2]>,
    /// The laser is lit.
    pub lit: bool,
}

impl FeedSample {
    /// The feed line (without its newline).
    pub fn line(&self) -> String {
        let lit = u8::from(self.lit);
        match self.spot_mm {
            // 1 µm resolution: far below what a camera resolves.
            Some([x, y]) => format!("{x:.4} {y:.4} {lit}"),
            None => format!("off-board {lit}"),
        }
    }

    /// Parses a feed line; `None` if it is not one.
    pub fn parse(line: &str) -> Option<Self> {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let lit = |s: &str| match s {
            "1" => Some(true),
            "0" => Some(false),
            _ => None,
        };
        match fields[..] {
            ["off-board", l] => Some(Self {
                spot_mm: None,
                lit: lit(l)?,
            }),
            [x, y, l] => {
                let (x, y): (f64, f64) = (x.parse().ok()?, y.parse().ok()?);
                (x.is_finite() && y.is_finite()).then_some(())?;
                Some(Self {
                    spot_mm: Some([x, y]),
                    lit: lit(l)?,
                })
            }
            _ => None,
        }
    }

    /// Reads the feed file at `path`.
    pub fn read(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            format!(
                "spot feed {}: {e} (start the simulator with `cargo xtask sim --pty LINK --spot-feed`)",
                path.display()
            )
        })?;
        Self::parse(text.trim()).ok_or_else(|| {
            format!(
                "spot feed {}: not a feed line: {:?}",
                path.display(),
                text.trim()
            )
        })
    }
}

/// The feed file beside the console's PTY link `link`: `LINK.spot`.
pub fn beside(link: &Path) -> PathBuf {
    let mut name = link.as_os_str().to_owned();
    name.push(".spot");
    PathBuf::from(name)
}

/// Writes `line` to `path` atomically.
fn publish(path: &Path, line: &str) {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let written =
        std::fs::write(&tmp, format!("{line}\n")).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = written {
        log::error!("spot feed {}: {e}", path.display());
    }
}

/// Publishes the spot (`spot_at`, cm) and the gimbal laser every
/// `period_us` while it changes.
pub async fn spot_feed(
    path: PathBuf,
    spot_at: SpotFn,
    recording: Rc<RefCell<Recording>>,
    period_us: u64,
) {
    let mut last = String::new();
    loop {
        let t_us = crate::clock::now_us();
        let sample = FeedSample {
            spot_mm: spot_at(t_us).map(|(x_cm, y_cm)| [mm_from_cm(x_cm), mm_from_cm(y_cm)]),
            lit: recording.borrow().laser_at(t_us),
        };
        let line = sample.line();
        if line != last {
            publish(&path, &line);
            last = line;
        }
        Timer::after_micros(period_us).await;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_round_trip_and_garbage_is_refused() {
        for s in [
            FeedSample {
                spot_mm: Some([-114.9612, 76.6401]),
                lit: true,
            },
            FeedSample {
                spot_mm: None,
                lit: false,
            },
        ] {
            assert_eq!(FeedSample::parse(&s.line()), Some(s));
        }
        for bad in ["", "1 2", "1 2 3", "nan 2 1", "off-board", "x y 1"] {
            assert_eq!(FeedSample::parse(bad), None, "{bad}");
        }
    }
}
