//! The lines of the outbound queue: what a line is and one taken for
//! writing (types only: the queue is in `outbound.rs`).

use crate::text::ReplyText;

/// What a queued line is; decides how it is printed and its priority.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LineKind {
    /// A data line of the current reply (printed as is).
    Data,
    /// The reply's closing `ok`.
    Ok,
    /// The reply's closing `error: <text>`.
    Error,
    /// An unsolicited notice, printed in brackets: `[<text>]`.
    Notice,
    /// The closing `error:<text>` of a G-code or `$` line (grbl's form,
    /// no space: the text is grbl's error number).
    GrblError,
}

impl LineKind {
    /// Whether this line closes a reply.
    pub fn is_closer(self) -> bool {
        matches!(self, LineKind::Ok | LineKind::Error | LineKind::GrblError)
    }

    /// The kind's code in a stored entry.
    pub(super) fn code(self) -> u8 {
        match self {
            LineKind::Data => 0,
            LineKind::Ok => 1,
            LineKind::Error => 2,
            LineKind::Notice => 3,
            LineKind::GrblError => 4,
        }
    }

    /// The kind stored as `code` (`None`: no line kind).
    pub(super) fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(LineKind::Data),
            1 => Some(LineKind::Ok),
            2 => Some(LineKind::Error),
            3 => Some(LineKind::Notice),
            4 => Some(LineKind::GrblError),
            _ => None,
        }
    }
}

/// One line taken from the queue for writing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutLine {
    /// What it is.
    pub kind: LineKind,
    /// Its text (without `error: `, brackets or line end).
    pub text: ReplyText,
}
