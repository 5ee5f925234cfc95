use super::*;
use embassy_time::{Duration, Instant, Timer};
use std::cell::RefCell;
use std::rc::Rc;

#[test]
fn virtual_time_jumps_over_sleeps() {
    let log: Rc<RefCell<Vec<(u64, &str)>>> = Rc::default();
    let wall = std::time::Instant::now();
    let (a, b) = (log.clone(), log.clone());
    let end = run(
        false,
        60_000_000,
        |spawner| {
            spawn(&spawner, async move {
                Timer::after(Duration::from_secs(10)).await;
                a.borrow_mut().push((Instant::now().as_micros(), "a"));
            });
            spawn(&spawner, async move {
                Timer::after(Duration::from_millis(1500)).await;
                b.borrow_mut().push((Instant::now().as_micros(), "b"));
            });
        },
        || false,
    );
    assert_eq!(end, RunEnd::Quiescent);
    assert_eq!(*log.borrow(), vec![(1_500_000, "b"), (10_000_000, "a")]);
    assert!(wall.elapsed() < std::time::Duration::from_secs(2));
}

#[test]
fn a_busy_loop_is_reported_not_run_forever() {
    let end = run(
        false,
        2_000_000,
        |spawner| {
            spawn(&spawner, async {
                loop {
                    embassy_futures::yield_now().await;
                }
            });
        },
        || false,
    );
    assert_eq!(end, RunEnd::Livelock);
    assert_eq!(clock::now_us(), 0);
}

#[test]
fn each_task_step_is_accounted_in_cpu_time() {
    let end = run(
        false,
        1_000_000,
        |spawner| {
            spawn_task(&spawner, "spinner", TaskKind::Firmware, async {
                for _ in 0..3 {
                    // Holds the executor for ~3 ms of CPU time.
                    let start = thread_cpu_ns();
                    while thread_cpu_ns() - start < 3_000_000 {
                        std::hint::black_box(0u64);
                    }
                    Timer::after_millis(10).await;
                }
            });
            spawn_task(&spawner, "sleeper", TaskKind::Simulator, async {
                Timer::after_millis(5).await;
            });
        },
        || false,
    );
    assert_eq!(end, RunEnd::Quiescent);
    let steps = task_steps();
    assert_eq!(steps.len(), 2);
    let spinner = &steps[0];
    assert_eq!(
        (spinner.name, spinner.kind),
        ("spinner", TaskKind::Firmware)
    );
    assert_eq!(spinner.polls, 4, "three spins and the end");
    assert!(spinner.max_cpu_ns >= 3_000_000, "{spinner:?}");
    assert_eq!(spinner.long_step_count, 3);
    let times: Vec<u64> = spinner.long_steps.iter().map(|&(t, _)| t).collect();
    assert_eq!(times, [0, 10_000, 20_000]);
    let sleeper = &steps[1];
    assert_eq!(sleeper.polls, 2);
    assert!(sleeper.max_cpu_ns < LONG_STEP_NS, "{sleeper:?}");
    assert_eq!(
        longest_poll(),
        std::time::Duration::from_nanos(spinner.max_cpu_ns)
    );
}

#[test]
fn simulator_work_is_not_a_firmware_step() {
    run(
        false,
        1_000_000,
        |spawner| {
            spawn_task(&spawner, "driver", TaskKind::Firmware, async {
                simulator_work(|| {
                    let start = thread_cpu_ns();
                    while thread_cpu_ns() - start < 3_000_000 {
                        std::hint::black_box(0u64);
                    }
                });
            });
        },
        || false,
    );
    let steps = task_steps();
    assert!(steps[0].max_cpu_ns < LONG_STEP_NS, "{:?}", steps[0]);
    assert_eq!(steps[0].long_step_count, 0);
}

#[test]
fn time_limit_ends_a_run_that_never_stops() {
    let end = run(
        false,
        2_000_000,
        |spawner| {
            spawn(&spawner, async {
                loop {
                    Timer::after_millis(100).await;
                }
            });
        },
        || false,
    );
    assert_eq!(end, RunEnd::TimeLimit);
    assert_eq!(clock::now_us(), 2_000_000);
}

fn steps_with(long: &[(u64, u64)], max: u64) -> TaskSteps {
    TaskSteps {
        long_steps: long.to_vec(),
        long_step_count: long.len() as u64,
        max_cpu_ns: max,
        max_at_us: long.iter().find(|s| s.1 == max).map_or(0, |s| s.0),
        ..TaskSteps::new("galvo", TaskKind::Firmware)
    }
}

#[test]
fn only_long_steps_that_recur_in_every_run_count() {
    // Run 1: a 4.09 ms spike at 20 ms (host load) and a real 2.5 ms step
    // at 50 ms; run 2: a 1.07 ms spike at 70 ms and the real step again
    // (2.2 ms); run 3: the real step only.
    let runs = vec![
        vec![steps_with(
            &[(20_000, 4_090_000), (50_000, 2_500_000)],
            4_090_000,
        )],
        vec![steps_with(
            &[(50_000, 2_200_000), (70_000, 1_070_000)],
            2_200_000,
        )],
        vec![steps_with(&[(50_000, 2_300_000)], 2_300_000)],
    ];
    let kept = recurring_steps(&runs);
    assert_eq!(kept[0].long_steps, [(50_000, 2_200_000)]);
    assert_eq!(kept[0].long_step_count, 1);
    assert_eq!((kept[0].max_cpu_ns, kept[0].max_at_us), (2_200_000, 50_000));
    assert_eq!(
        longest_firmware_step(&kept),
        std::time::Duration::from_nanos(2_200_000)
    );
    // Spikes at different polls in each run: nothing recurs, and the
    // longest step is at most the limit.
    let noisy = vec![
        vec![steps_with(&[(20_000, 4_090_000)], 4_090_000)],
        vec![steps_with(&[(70_000, 1_070_000)], 1_070_000)],
    ];
    let kept = recurring_steps(&noisy);
    assert!(kept[0].long_steps.is_empty() && kept[0].long_step_count == 0);
    assert_eq!(kept[0].max_cpu_ns, LONG_STEP_NS);
    // One run is itself.
    let one = vec![steps_with(&[(50_000, 2_500_000)], 2_500_000)];
    assert_eq!(recurring_steps(std::slice::from_ref(&one)), one);
}
