//! Reproducible random campaigns: a small generator and the random
//! command script of the galvo campaigns.

/// A xorshift64 random number generator: fixed seeds make reproducible
/// random campaigns without a dependency.
#[derive(Debug, Clone)]
pub struct XorShift(pub u64);

impl XorShift {
    /// The next pseudo-random number (never 0 for a non-zero seed).
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }

    /// A number in `0..n` (`n` > 0).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n.max(1)
    }

    /// One of `items` (not empty), chosen with [`below`](Self::below).
    pub fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len() as u64) as usize]
    }
}

/// The 1000 meaningful commands in random order and timing of
/// `galvo_sim.rs`'s random test (actuators, planners, grid and path
/// patterns, gotos, stops, parameter changes), then `stop` and the status.
pub fn random_meaningful_commands() -> String {
    let templates: &[&dyn Fn(u64) -> String] = &[
        &|_| "target galvo".into(),
        &|_| "target gimbal".into(),
        &|_| "target both".into(),
        &|r| format!("planner {}", if r % 2 == 0 { "optimal" } else { "seed" }),
        &|r| {
            format!(
                "pattern {} once",
                ["corner", "home", "horizontal", "vertical"][(r % 4) as usize]
            )
        },
        &|_| "pattern tuning 1 -1 5".into(),
        &|_| "pattern circle -3 2 2.5 ccw".into(),
        &|_| "pattern rect -4 3 4 -3 once".into(),
        &|r| format!("goto {} {}", (r % 17) as f64 - 8.0, (r % 11) as f64 - 5.0),
        &|_| "stop".into(),
        &|r| format!("set dwell_ms {}", r % 120),
        &|r| format!("set galvo.mark_speed_mm_s {}", 200 + r % 3000),
        &|r| format!("set galvo.laser_on_delay_us {}", r % 400),
        &|r| format!("wait {}", r % 80),
    ];
    let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
    let mut script = String::new();
    for _ in 0..1000 {
        let pick = (rng.next_u64() % templates.len() as u64) as usize;
        script.push_str(&templates[pick](rng.next_u64()));
        script.push('\n');
    }
    script.push_str("stop\nwait 20\nstatus\ngalvo status\n");
    script
}
