use super::*;
use crate::ring::Ring;
use proptest::prelude::*;
use std::vec;
use std::vec::Vec;

#[test]
fn dhr12rd_puts_x_low_and_y_high_and_saturates() {
    assert_eq!(dhr12rd(0xABC, 0x123), 0x0123_0ABC);
    assert_eq!(dhr12rd(0, 4095), 0x0FFF_0000);
    assert_eq!(dhr12rd(5000, u16::MAX), 0x0FFF_0FFF);
}

#[test]
fn bsrr_words_set_low_half_reset_high_half() {
    assert_eq!(bsrr_set(0), 1);
    assert_eq!(bsrr_reset(0), 1 << 16);
    assert_eq!(bsrr_set(15), 1 << 15);
    assert_eq!(bsrr_reset(15), 1 << 31);
    assert_eq!(laser_word(0, false, false), 0, "dark stays hands-off");
    assert_eq!(laser_word(0, false, true), 1 << 16);
    assert_eq!(laser_word(0, true, true), 1);
}

/// The ring as the hardware plays it: at update `u` the DAC outputs the
/// holding register (loaded at update `u - 1`) while the laser stream
/// writes BSRR word `u mod len`, then the DAC stream loads word `u mod len`; the loop
/// refills half `h + 1` when the DMA starts half `h`. Returns, per update
/// from 1 on, the output (DAC word, laser pin).
fn play(half_len: usize, halves: &[Vec<(u16, u16, bool)>], pin_start: bool) -> Vec<(u32, bool)> {
    let ring = Ring::new(half_len);
    let (mut dac, mut laser) = (vec![0u32; ring.samples()], vec![0u32; ring.samples()]);
    let mut track = LaserTrack::new(3);
    let mut write = |h: usize, dac: &mut [u32], laser: &mut [u32]| {
        let range = ring.range(h % 2);
        let samples = halves.get(h).cloned().unwrap_or_default();
        track.pack(0, true, samples, &mut dac[range.clone()], &mut laser[range]);
    };
    write(0, &mut dac, &mut laser);
    write(1, &mut dac, &mut laser);
    let (mut holding, mut pin) = (0u32, pin_start);
    let mut out = Vec::new();
    for u in 0..halves.len() * half_len + 1 {
        let word = laser[u % ring.samples()];
        if word & bsrr_set(3) != 0 {
            pin = true;
        }
        if word & bsrr_reset(3) != 0 {
            pin = false;
        }
        if u > 0 {
            out.push((holding, pin));
        }
        holding = dac[u % ring.samples()];
        if u % half_len == 0 && u / half_len >= 1 {
            write(u / half_len + 1, &mut dac, &mut laser);
        }
    }
    out
}

proptest! {
    /// Laser edges sit on the DAC's sample boundaries: at every update the
    /// pin shows exactly the laser bit of the sample the DAC outputs.
    #[test]
    fn laser_follows_the_dac_sample_it_belongs_to(
        half_len in 1usize..12,
        halves in prop::collection::vec(
            prop::collection::vec((0u16..4096, 0u16..4096, any::<bool>()), 12), 1..8),
    ) {
        let halves: Vec<Vec<_>> = halves.into_iter().map(|h| h[..half_len].to_vec()).collect();
        let played = play(half_len, &halves, false);
        let expected: Vec<(u32, bool)> = halves
            .iter()
            .flatten()
            .map(|&(x, y, lit)| (dhr12rd(x, y), lit))
            .collect();
        prop_assert_eq!(played, expected);
    }
}

#[test]
fn a_dark_stream_leaves_the_gimbal_laser_alone() {
    let dark = vec![vec![(1, 2, false); 4]; 3];
    assert!(play(4, &dark, true).iter().all(|&(_, pin)| pin));
    // A lit stretch ends with one reset, then hands off again.
    let mut halves = dark.clone();
    halves[1][1] = (1, 2, true);
    let played = play(4, &halves, false);
    let pins: Vec<bool> = played.iter().map(|&(_, pin)| pin).collect();
    assert_eq!(pins.iter().filter(|&&p| p).count(), 1);
    assert!(pins[5]);
}

#[test]
fn a_closed_gate_or_a_new_generation_darkens_the_carry() {
    let mut track = LaserTrack::new(0);
    let (mut dac, mut laser) = ([0u32; 2], [0u32; 2]);
    track.pack(7, true, [(0, 0, true), (0, 0, true)], &mut dac, &mut laser);
    assert_eq!(laser, [0, bsrr_set(0)]);
    // Still lit, same generation: the carried word lights slot 0.
    track.pack(7, true, [(0, 0, true), (0, 0, true)], &mut dac, &mut laser);
    assert_eq!(laser[0], bsrr_set(0));
    // The gate closed: nothing lights, not even the carry.
    track.pack(7, false, [(0, 0, true), (0, 0, true)], &mut dac, &mut laser);
    assert_eq!(laser, [0, 0]);
    track.pack(7, true, [(0, 0, true), (0, 0, true)], &mut dac, &mut laser);
    // A new generation starts dark too.
    track.pack(
        8,
        true,
        [(0, 0, false), (0, 0, false)],
        &mut dac,
        &mut laser,
    );
    assert_eq!(laser, [0, 0]);
}

#[test]
fn a_short_half_repeats_the_last_position_dark() {
    let mut track = LaserTrack::new(0);
    let (mut dac, mut laser) = ([9u32; 3], [9u32; 3]);
    track.pack(0, true, [(5, 6, true)], &mut dac, &mut laser);
    assert_eq!(dac, [dhr12rd(5, 6); 3]);
    assert_eq!(laser, [0, bsrr_set(0), bsrr_reset(0)]);
}

#[test]
fn a_hold_replays_identically_only_once_its_carry_is_its_own() {
    let mut track = LaserTrack::new(0);
    let (mut dac, mut laser) = ([0u32; 4], [0u32; 4]);
    track.pack(0, true, [(7, 7, true); 4], &mut dac, &mut laser);
    // Lit hold after nothing: slot 0 is still the dark carry.
    assert!(!replays_identically(&dac, &laser));
    track.pack(0, true, [(7, 7, true); 4], &mut dac, &mut laser);
    assert!(
        replays_identically(&dac, &laser),
        "lit hold, set everywhere"
    );
    track.pack(0, true, [(7, 7, false); 4], &mut dac, &mut laser);
    assert!(
        !replays_identically(&dac, &laser),
        "slot 0 sets, slot 1 resets"
    );
    track.pack(0, true, [(7, 7, false); 4], &mut dac, &mut laser);
    assert!(replays_identically(&dac, &laser), "dark hold, hands off");
    assert_eq!(laser, [0; 4]);
    let moving = [(7, 7, false), (7, 8, false), (7, 9, false), (7, 9, false)];
    track.pack(0, true, moving, &mut dac, &mut laser);
    assert!(!replays_identically(&dac, &laser), "the mirrors move");
}
