//! Counts of lines the outbound queue dropped, and the notice telling them.

use core::fmt;

use super::line::{LineKind, OutLine};
use crate::text::reply_text;

/// Lines dropped because the queue was full.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dropped {
    /// Data lines of replies.
    pub data_lines: u32,
    /// Notices (faults, recoveries).
    pub notices: u32,
}

impl Dropped {
    /// Whether nothing was dropped.
    pub fn is_empty(&self) -> bool {
        self.data_lines == 0 && self.notices == 0
    }

    pub(super) fn count(&mut self, kind: LineKind) {
        match kind {
            LineKind::Data => self.data_lines = self.data_lines.saturating_add(1),
            LineKind::Notice => self.notices = self.notices.saturating_add(1),
            // Closers always have room (see the module doc); should one
            // ever be refused it is counted with the data lines.
            LineKind::Ok | LineKind::Error | LineKind::GrblError => {
                self.data_lines = self.data_lines.saturating_add(1)
            }
        }
    }
}

/// The notice reporting dropped lines (`info:` for reply lines only,
/// `error:` when notices, which may report faults, were lost too).
impl fmt::Display for Dropped {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plural = |n: u32| if n == 1 { "" } else { "s" };
        let (lines, notices) = (self.data_lines, self.notices);
        if notices == 0 {
            write!(f, "info: {lines} reply line{}", plural(lines))?;
        } else {
            write!(f, "error: {notices} notice{}", plural(notices))?;
            if lines > 0 {
                write!(f, " and {lines} reply line{}", plural(lines))?;
            }
        }
        f.write_str(" dropped while the host was not reading")?;
        if notices > 0 {
            f.write_str("; `status` shows faults")?;
        }
        Ok(())
    }
}

/// The notice reporting `dropped`.
pub(super) fn dropped_notice(dropped: Dropped) -> OutLine {
    OutLine {
        kind: LineKind::Notice,
        text: reply_text(format_args!("{dropped}")),
    }
}
