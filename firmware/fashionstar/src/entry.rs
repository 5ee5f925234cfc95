//! The per-servo moves (codes 8, 11 and 12) and their layout, shared by
//! the single-servo frame and the entries of a sync frame (code 25), which
//! carry each servo's payload as the single frame would
//! (`FSUS_SyncCommand`):
//!
//! | code | move | payload (= sync entry) |
//! |---|---|---|
//! | 8 | set angle | `id u8, angle i16 (0.1°), interval u16 (ms), power u16 (mW)` |
//! | 11 | set angle by interval | `id, angle i16, interval u16, t_acc u16, t_dec u16, power u16` |
//! | 12 | set angle by velocity | `id, angle i16, velocity u16 (0.1°/s), t_acc u16, t_dec u16, power u16` |
//!
//! Every layout is `id u8, angle i16`, then `u16` fields: one [`Entry`]
//! codec writes and reads all three.

use heapless::Vec;

use crate::wire::{PayloadWriter, Reader};
use crate::{
    ANGLE_LIMIT_TENTHS_DEG, DecodeError, MAX_SYNC_SERVOS, MAX_VELOCITY_TENTHS_DEG_S,
    MIN_ACC_DEC_MS, MIN_VELOCITY_TENTHS_DEG_S, code,
};

const _: () = assert!(MAX_SYNC_SERVOS >= 2 && MAX_SYNC_SERVOS <= u8::MAX as usize);

/// Per-servo entries of one sync frame (at most [`MAX_SYNC_SERVOS`]).
pub type SyncEntries<T> = Vec<T, MAX_SYNC_SERVOS>;

/// Move to an angle within a time (code 8; also the sync entry with
/// inner code 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetAngle {
    /// Servo id.
    pub id: u8,
    /// Target angle, 0.1° (the servo's range is ±1800).
    pub angle_tenths_deg: i16,
    /// Time to get there, ms.
    pub interval_ms: u16,
    /// Power limit, mW (0: the servo's own limit).
    pub power_mw: u16,
}

/// Move to an angle within a time with acceleration and deceleration
/// phases (code 11; also the sync entry with inner code 11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetAngleByInterval {
    /// Servo id.
    pub id: u8,
    /// Target angle, 0.1°.
    pub angle_tenths_deg: i16,
    /// Time to get there, ms.
    pub interval_ms: u16,
    /// Acceleration time, ms (the SDK sends at least 20).
    pub t_acc_ms: u16,
    /// Deceleration time, ms (the SDK sends at least 20).
    pub t_dec_ms: u16,
    /// Power limit, mW (0: the servo's own limit).
    pub power_mw: u16,
}

/// Move to an angle at a velocity with acceleration and deceleration
/// phases (code 12; also the sync entry with inner code 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SetAngleByVelocity {
    /// Servo id.
    pub id: u8,
    /// Target angle, 0.1°.
    pub angle_tenths_deg: i16,
    /// Cruise velocity, 0.1°/s (the SDK sends 10..=7500).
    pub velocity_tenths_deg_s: u16,
    /// Acceleration time, ms (the SDK sends at least 20).
    pub t_acc_ms: u16,
    /// Deceleration time, ms (the SDK sends at least 20).
    pub t_dec_ms: u16,
    /// Power limit, mW (0: the servo's own limit).
    pub power_mw: u16,
}

fn clamp_angle(angle_tenths_deg: i16) -> i16 {
    angle_tenths_deg.clamp(-ANGLE_LIMIT_TENTHS_DEG, ANGLE_LIMIT_TENTHS_DEG)
}

impl SetAngle {
    /// The request as the vendor SDK would send it: angle clamped to
    /// ±180.0°.
    pub fn with_sdk_limits(self) -> Self {
        Self {
            angle_tenths_deg: clamp_angle(self.angle_tenths_deg),
            ..self
        }
    }
}

impl SetAngleByInterval {
    /// The request as the vendor SDK would send it: angle clamped to
    /// ±180.0°, acceleration and deceleration times at least 20 ms.
    pub fn with_sdk_limits(self) -> Self {
        Self {
            angle_tenths_deg: clamp_angle(self.angle_tenths_deg),
            t_acc_ms: self.t_acc_ms.max(MIN_ACC_DEC_MS),
            t_dec_ms: self.t_dec_ms.max(MIN_ACC_DEC_MS),
            ..self
        }
    }
}

impl SetAngleByVelocity {
    /// The request as the vendor SDK would send it: angle clamped to
    /// ±180.0°, velocity to 1..=750 °/s, acceleration and deceleration
    /// times at least 20 ms.
    pub fn with_sdk_limits(self) -> Self {
        Self {
            angle_tenths_deg: clamp_angle(self.angle_tenths_deg),
            velocity_tenths_deg_s: self
                .velocity_tenths_deg_s
                .clamp(MIN_VELOCITY_TENTHS_DEG_S, MAX_VELOCITY_TENTHS_DEG_S),
            t_acc_ms: self.t_acc_ms.max(MIN_ACC_DEC_MS),
            t_dec_ms: self.t_dec_ms.max(MIN_ACC_DEC_MS),
            ..self
        }
    }
}

/// A per-servo move that can travel alone or inside a sync frame: `id
/// u8, angle i16`, then `N` `u16` fields, little-endian.
pub(crate) trait Entry<const N: usize>: Sized {
    /// Code of the move (the inner code in a sync frame).
    const CODE: u8;
    /// Payload length, bytes (the per-servo length in a sync frame).
    const LEN: u8 = (3 + 2 * N) as u8;

    /// The id, the angle (0.1°) and the `u16` fields in wire order.
    fn to_fields(&self) -> (u8, i16, [u16; N]);

    /// The move from [`Entry::to_fields`]'s parts.
    fn from_fields(id: u8, angle_tenths_deg: i16, fields: [u16; N]) -> Self;

    /// Id of the servo the move is for.
    fn servo_id(&self) -> u8 {
        self.to_fields().0
    }

    /// Appends the payload.
    fn write(&self, w: &mut PayloadWriter) {
        let (id, angle_tenths_deg, fields) = self.to_fields();
        w.u8(id);
        w.i16(angle_tenths_deg);
        for field in &fields {
            w.u16(*field);
        }
    }

    /// Reads one payload; `None` when the bytes run out.
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        let id = r.u8()?;
        let angle_tenths_deg = r.i16()?;
        let mut fields = [0u16; N];
        for field in &mut fields {
            *field = r.u16()?;
        }
        Some(Self::from_fields(id, angle_tenths_deg, fields))
    }
}

impl Entry<2> for SetAngle {
    const CODE: u8 = code::SET_ANGLE;
    fn to_fields(&self) -> (u8, i16, [u16; 2]) {
        (
            self.id,
            self.angle_tenths_deg,
            [self.interval_ms, self.power_mw],
        )
    }
    fn from_fields(id: u8, angle_tenths_deg: i16, [interval_ms, power_mw]: [u16; 2]) -> Self {
        Self {
            id,
            angle_tenths_deg,
            interval_ms,
            power_mw,
        }
    }
}

impl Entry<4> for SetAngleByInterval {
    const CODE: u8 = code::SET_ANGLE_BY_INTERVAL;
    fn to_fields(&self) -> (u8, i16, [u16; 4]) {
        let Self {
            id,
            angle_tenths_deg,
            interval_ms,
            t_acc_ms,
            t_dec_ms,
            power_mw,
        } = *self;
        (
            id,
            angle_tenths_deg,
            [interval_ms, t_acc_ms, t_dec_ms, power_mw],
        )
    }
    fn from_fields(id: u8, angle_tenths_deg: i16, fields: [u16; 4]) -> Self {
        let [interval_ms, t_acc_ms, t_dec_ms, power_mw] = fields;
        Self {
            id,
            angle_tenths_deg,
            interval_ms,
            t_acc_ms,
            t_dec_ms,
            power_mw,
        }
    }
}

impl Entry<4> for SetAngleByVelocity {
    const CODE: u8 = code::SET_ANGLE_BY_VELOCITY;
    fn to_fields(&self) -> (u8, i16, [u16; 4]) {
        let Self {
            id,
            angle_tenths_deg,
            velocity_tenths_deg_s,
            t_acc_ms,
            t_dec_ms,
            power_mw,
        } = *self;
        let fields = [velocity_tenths_deg_s, t_acc_ms, t_dec_ms, power_mw];
        (id, angle_tenths_deg, fields)
    }
    fn from_fields(id: u8, angle_tenths_deg: i16, fields: [u16; 4]) -> Self {
        let [velocity_tenths_deg_s, t_acc_ms, t_dec_ms, power_mw] = fields;
        Self {
            id,
            angle_tenths_deg,
            velocity_tenths_deg_s,
            t_acc_ms,
            t_dec_ms,
            power_mw,
        }
    }
}

/// Appends a sync payload: `inner code, per-servo length, count`, then
/// each entry.
pub(crate) fn write_sync<const N: usize, T: Entry<N>>(w: &mut PayloadWriter, entries: &[T]) {
    w.u8(T::CODE);
    w.u8(T::LEN);
    // At most MAX_SYNC_SERVOS (≤ 255, asserted above) entries.
    w.u8(entries.len() as u8);
    for entry in entries {
        entry.write(w);
    }
}

/// Reads the `count` entries of a sync payload whose per-servo length byte
/// was `len` (the rest of `r`); `BadSync` when they disagree with `T`.
pub(crate) fn read_sync<const N: usize, T: Entry<N>>(
    count: u8,
    len: u8,
    r: &mut Reader<'_>,
) -> Result<SyncEntries<T>, DecodeError> {
    let bad = DecodeError::BadSync {
        inner_code: T::CODE,
    };
    if len != T::LEN || r.rest().len() != usize::from(count) * usize::from(len) {
        return Err(bad);
    }
    let mut entries = SyncEntries::new();
    for _ in 0..count {
        let entry = T::read(r).ok_or(bad)?;
        entries.push(entry).map_err(|_| bad)?;
    }
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_lengths_are_the_sdks() {
        // `FSUS_SyncCommand`: 7 bytes per set-angle entry, 11 per
        // by-interval or by-velocity entry.
        assert_eq!(<SetAngle as Entry<2>>::LEN, 7);
        assert_eq!(<SetAngleByInterval as Entry<4>>::LEN, 11);
        assert_eq!(<SetAngleByVelocity as Entry<4>>::LEN, 11);
    }
}
