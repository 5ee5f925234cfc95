use super::*;
use crate::executor;
use laser_app::laser_gate::LaserGate;

/// 100 samples of 10 µs: 1 ms halves.
const HALF: usize = 100;
const PERIOD_NS: u64 = 10_000;

fn lit(x_code: u16) -> DacSample {
    DacSample {
        x_code,
        y_code: 2048,
        laser: true,
    }
}

fn half(samples: &[DacSample], generation: u32) -> Half<'_> {
    Half {
        samples,
        generation,
        computed: samples.len(),
        work: Default::default(),
    }
}

/// Runs `body` with a DAC (cost `cost_ns` per sample) and a recorded
/// gate; returns the recording.
fn with_dac<F>(
    cost_ns: u64,
    body: impl FnOnce(SimDac, &'static LaserGate) -> F + 'static,
) -> DacRecording
where
    F: Future<Output = ()> + 'static,
{
    let recording = Rc::new(RefCell::new(DacRecording::default()));
    let gate = crate::laser::recorded_gate(&recording);
    let dac = SimDac::new(HALF, PERIOD_NS, cost_ns, recording.clone());
    let done = Rc::new(Cell::new(false));
    let finished = done.clone();
    let end = executor::run(
        false,
        1_000_000,
        move |spawner| {
            executor::spawn(&spawner, async move {
                body(dac, gate).await;
                finished.set(true);
            })
        },
        move || done.get(),
    );
    assert_eq!(end, executor::RunEnd::Stopped);
    recording.borrow().clone()
}

#[test]
fn output_starts_once_both_halves_are_primed_and_is_gapless() {
    let rec = with_dac(5_000, |mut dac, gate| async move {
        assert!(gate.open(0));
        let a = [lit(100); HALF];
        let b = [lit(200); HALF];
        // Priming is never late, however slow the loop.
        assert!(dac.write_half(half(&a, 0)).await.is_ok());
        assert!(dac.write_half(half(&b, 0)).await.is_ok());
        for _ in 0..3 {
            assert!(dac.write_half(half(&a, 0)).await.is_ok());
        }
    });
    assert!(rec.underruns.is_empty());
    let samples: Vec<_> = rec.iter().collect();
    assert_eq!(samples.len(), 5 * HALF);
    for w in samples.windows(2) {
        assert_eq!(w[1].0 - w[0].0, PERIOD_NS, "gapless");
    }
    assert!(samples.iter().all(|(_, s)| s.laser));
}

#[test]
fn a_late_half_is_an_underrun_and_its_replay_is_dark() {
    let rec = with_dac(0, |mut dac, gate| async move {
        assert!(gate.open(0));
        let a = [lit(100); HALF];
        let b = [lit(200); HALF];
        dac.write_half(half(&a, 0)).await.unwrap();
        dac.write_half(half(&b, 0)).await.unwrap();
        // Late by two and a half halves.
        Timer::after_micros(3_500).await;
        let late = dac.write_half(half(&a, 0)).await;
        assert_eq!(late, Err(Underrun { halves: 2 }));
    });
    assert_eq!(rec.underruns, vec![(2 * HALF, 2)]);
    let samples: Vec<_> = rec.iter().map(|(_, s)| s).collect();
    assert_eq!(samples.len(), 5 * HALF);
    assert!(samples[..2 * HALF].iter().all(|s| s.laser));
    // The stale replays keep their codes (the mirrors get them) but
    // never the laser.
    assert!(samples[2 * HALF..4 * HALF].iter().all(|s| !s.laser));
    assert_eq!(samples[2 * HALF].x_code, 100);
    assert_eq!(samples[3 * HALF].x_code, 200);
    assert!(samples[4 * HALF..].iter().all(|s| s.laser));
}

#[test]
fn closing_the_gate_darkens_samples_already_handed_over() {
    let rec = with_dac(0, |mut dac, gate| async move {
        assert!(gate.open(0));
        let a = [lit(100); HALF];
        dac.write_half(half(&a, 0)).await.unwrap();
        dac.write_half(half(&a, 0)).await.unwrap();
        // Both halves (2 ms of lit samples) are in the DAC.
        Timer::after_micros(500).await;
        let generation = gate.close();
        // A half computed before the close stays dark even once the
        // gate is open again for a new run; the new run's half shines.
        dac.write_half(half(&a, 0)).await.unwrap();
        assert!(gate.open(generation));
        dac.write_half(half(&[lit(300); HALF], generation))
            .await
            .unwrap();
    });
    let samples: Vec<_> = rec.iter().collect();
    assert_eq!(samples.len(), 4 * HALF);
    for (t_ns, s) in &samples {
        let want = *t_ns < 500_000 || s.x_code == 300;
        assert_eq!(s.laser, want, "at {t_ns} ns");
    }
    // The stream itself was lit: only the gate made it dark.
    assert!(rec.stream_runs().all(|(_, _, _, s, _)| s.laser));
}

#[test]
fn repeating_a_hold_costs_nothing_and_is_never_an_underrun() {
    let hold = DacSample {
        x_code: 2048,
        y_code: 2048,
        laser: false,
    };
    // 1 ms per computed sample: any written half would be late.
    let rec = with_dac(1_000_000, move |mut dac, _| async move {
        let h = [hold; HALF];
        assert!(!dac.holds(hold), "not before it is primed");
        // Both halves of the double buffer.
        for _ in 0..2 {
            dac.write_half(Half {
                samples: &h,
                generation: 0,
                computed: 0,
                work: Default::default(),
            })
            .await
            .unwrap();
        }
        assert!(dac.holds(hold));
        assert!(!dac.holds(DacSample { x_code: 0, ..hold }));
        for i in 0..200 {
            dac.repeat_half().await;
            if i % 17 == 0 {
                // The loop is late now and then: still just a replay.
                Timer::after_micros(2_700).await;
            }
        }
    });
    assert!(rec.underruns.is_empty());
    let samples: Vec<_> = rec.iter().collect();
    assert!(samples.len() >= 202 * HALF);
    for w in samples.windows(2) {
        assert_eq!(w[1].0 - w[0].0, PERIOD_NS, "gapless");
    }
    assert!(samples.iter().all(|(_, s)| *s == hold));
}
