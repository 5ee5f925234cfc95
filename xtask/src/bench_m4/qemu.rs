//! Running the bench on QEMU's Cortex-M4F board.

use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

use crate::toolchain::run;

/// The whole run may take this long (wall clock) before it is killed.
const RUN_TIMEOUT: Duration = Duration::from_secs(120);

/// The emulated machine: the MPS2 AN386 (Cortex-M4F) with `-icount
/// shift=0` (1 ns of virtual time per instruction while running; while the
/// CPU sleeps in WFI, virtual time follows the host clock).
pub(crate) const MACHINE_ARGS: [&str; 6] = [
    "-machine",
    "mps2-an386",
    "-cpu",
    "cortex-m4",
    "-icount",
    "shift=0",
];

/// Installs Debian's `qemu-system-arm` when it is missing.
pub(crate) fn ensure_qemu() -> Result<()> {
    if Command::new("qemu-system-arm")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
    {
        return Ok(());
    }
    println!(
        "qemu-system-arm not found: installing it (apt-get update && apt-get install -y qemu-system-arm)"
    );
    run("apt-get", &["update"]).context("apt-get update (needs root)")?;
    run("apt-get", &["install", "-y", "qemu-system-arm"])
        .context("could not install qemu-system-arm; install it and run again")
}

/// Runs the bench ELF on QEMU and returns its output; fails on a non-zero
/// exit or when it runs longer than [`RUN_TIMEOUT`].
pub(super) fn run_qemu(elf: &PathBuf) -> Result<String> {
    let mut child = Command::new("qemu-system-arm")
        .args(MACHINE_ARGS)
        .args([
            "-nographic",
            "-semihosting-config",
            "enable=on,target=native",
            "-kernel",
        ])
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("could not start qemu-system-arm")?;
    // Semihosting prints on QEMU's stderr; read both pipes on threads so a
    // full pipe never stalls the guest.
    let reader = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_string(&mut text);
            }
            text
        })
    };
    let stdout = reader(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let stderr = reader(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > RUN_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            bail!("bench-m4 ran longer than {RUN_TIMEOUT:?} on QEMU: killed");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut out = stdout.join().unwrap_or_default();
    out.push_str(&stderr.join().unwrap_or_default());
    if !status.success() {
        bail!("bench-m4 failed on QEMU ({status}):\n{out}");
    }
    Ok(out)
}
