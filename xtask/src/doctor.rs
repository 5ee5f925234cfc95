//! `cargo xtask doctor [--port DEVICE]`: checks what the first hour with a
//! board needs and says, line by line, what is fine and what to do about
//! the rest — the Rust target and components, flip-link, probe-rs, the
//! udev rules, connected probes, the board's USB console and the user's
//! permission on it, and (with a port) whether the firmware answers and
//! was built from this checkout.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Duration;

use crate::toolchain::{TARGET, workspace_root};

/// Options of `cargo xtask doctor`.
#[derive(clap::Args, Debug)]
pub struct DoctorArgs {
    /// The board's console (e.g. /dev/ttyACM0, or a simulator's or QEMU
    /// board's PTY): check that the firmware answers `version` and was
    /// built from this checkout.
    #[arg(long)]
    port: Option<PathBuf>,
}

/// How a check came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Fine.
    Ok,
    /// Must be fixed before the board can be used (the line says how).
    Fix,
    /// Worth knowing, nothing broken (e.g. no board plugged in yet).
    Note,
}

/// One line of the report.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    pub verdict: Verdict,
    /// What was checked.
    pub what: String,
    /// What was found.
    pub detail: String,
    /// The command or step that fixes it.
    pub fix: Option<String>,
}

impl Finding {
    fn ok(what: &str, detail: impl Into<String>) -> Self {
        Self {
            verdict: Verdict::Ok,
            what: what.to_owned(),
            detail: detail.into(),
            fix: None,
        }
    }
    fn fix(what: &str, detail: impl Into<String>, fix: impl Into<String>) -> Self {
        Self {
            verdict: Verdict::Fix,
            what: what.to_owned(),
            detail: detail.into(),
            fix: Some(fix.into()),
        }
    }
    fn note(what: &str, detail: impl Into<String>, hint: impl Into<String>) -> Self {
        Self {
            verdict: Verdict::Note,
            what: what.to_owned(),
            detail: detail.into(),
            fix: Some(hint.into()),
        }
    }
}

/// The udev rules file shipped with the firmware.
pub const UDEV_RULES: &str = "firmware/udev/69-laser-pointer.rules";
/// USB ids of ST-LINK probes (vendor 0483).
const STLINK_PRODUCTS: [&str; 5] = ["3748", "374b", "374e", "374f", "3753"];
/// The firmware console's USB vendor and product id (`firmware/src/board.rs`).
pub const CONSOLE_USB_ID: (&str, &str) = ("c0de", "cafe");

/// The firmware target among `rustup target list --installed`'s lines.
pub fn check_target(installed: &str) -> Finding {
    if installed.lines().any(|l| l.trim() == TARGET) {
        Finding::ok("Rust target", TARGET)
    } else {
        Finding::fix(
            "Rust target",
            format!("{TARGET} is not installed"),
            format!("rustup target add {TARGET}"),
        )
    }
}

/// The components the project uses among `rustup component list
/// --installed`'s lines.
pub fn check_components(installed: &str) -> Vec<Finding> {
    ["rustfmt", "clippy", "llvm-tools"]
        .iter()
        .map(|c| {
            let there = installed
                .lines()
                .any(|l| l.trim() == *c || l.trim().starts_with(&format!("{c}-")));
            if there {
                Finding::ok("Rust component", *c)
            } else {
                Finding::fix(
                    "Rust component",
                    format!("{c} is not installed"),
                    format!("rustup component add {c}"),
                )
            }
        })
        .collect()
}

/// A tool on PATH: `found` is its version text (or that it started).
pub fn check_tool(name: &str, found: Option<String>, install: &str, why: &str) -> Finding {
    match found {
        Some(version) => Finding::ok(name, version),
        None => Finding::fix(name, format!("not installed ({why})"), install),
    }
}

/// udev rules (`rules`: file path and text of each rules file) that give
/// the user the ST-LINK and the console.
pub fn check_udev(rules: &[(PathBuf, String)]) -> Finding {
    let covers = |vendor: &str, product: &str| {
        rules.iter().any(|(_, text)| {
            text.lines().any(|l| {
                let l = l.to_ascii_lowercase();
                !l.trim_start().starts_with('#')
                    && l.contains(&format!("\"{vendor}\""))
                    && l.contains(&format!("\"{product}\""))
            })
        })
    };
    let stlink = STLINK_PRODUCTS.iter().any(|p| covers("0483", p));
    let console = covers(CONSOLE_USB_ID.0, CONSOLE_USB_ID.1);
    let install = format!(
        "sudo cp {UDEV_RULES} /etc/udev/rules.d/ && sudo udevadm control --reload && sudo udevadm trigger (then re-plug the board)"
    );
    match (stlink, console) {
        (true, true) => Finding::ok("udev rules", "ST-LINK and the board's console"),
        (false, false) => {
            Finding::fix("udev rules", "none for the ST-LINK or the console", install)
        }
        (true, false) => Finding::fix("udev rules", "the ST-LINK's, not the console's", install),
        (false, true) => Finding::fix("udev rules", "the console's, not the ST-LINK's", install),
    }
}

/// `probe-rs list`'s output: which probes are connected.
pub fn check_probes(listing: Option<&str>) -> Finding {
    let Some(listing) = listing else {
        return Finding::note(
            "debug probe",
            "not checked (probe-rs is not installed)",
            "install probe-rs, then `probe-rs list`",
        );
    };
    let probes: Vec<&str> = listing
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with('['))
        .collect();
    if probes.is_empty() {
        Finding::note(
            "debug probe",
            "no probe connected",
            "plug the STM32F4DISCOVERY's ST-LINK port (mini-USB, CN1), check with `probe-rs list`",
        )
    } else {
        Finding::ok("debug probe", probes.join("; "))
    }
}

/// The board consoles (`/dev/ttyACM*` whose USB device is the firmware's)
/// under the sysfs root `sys` (`/sys` on a real machine).
pub fn find_consoles(sys: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(sys.join("class/tty")) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with("ttyACM"))
        .filter(|e| {
            // device -> the USB interface; its parent holds the ids.
            let usb = e.path().join("device/..");
            let id = |name: &str| {
                std::fs::read_to_string(usb.join(name))
                    .map(|s| s.trim().to_ascii_lowercase())
                    .unwrap_or_default()
            };
            id("idVendor") == CONSOLE_USB_ID.0 && id("idProduct") == CONSOLE_USB_ID.1
        })
        .map(|e| Path::new("/dev").join(e.file_name()))
        .collect();
    found.sort();
    found
}

/// Whether the board's console was found.
pub fn check_consoles(found: &[PathBuf]) -> Finding {
    if found.is_empty() {
        Finding::note(
            "board console",
            "no board console (USB 0xc0de:0xcafe) found",
            "flash the firmware (`cargo xtask flash`), plug the board's micro-USB port (CN5), check with `ls /dev/ttyACM*`",
        )
    } else {
        let names: Vec<String> = found.iter().map(|p| p.display().to_string()).collect();
        Finding::ok("board console", names.join(", "))
    }
}

/// Whether the user can open `port` (the error of opening it, if any).
pub fn check_access(port: &Path, opened: Result<(), std::io::Error>) -> Finding {
    match opened {
        Ok(()) => Finding::ok(
            "port access",
            format!("{} opens read-write", port.display()),
        ),
        Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => Finding::fix(
            "port access",
            format!("{}: permission denied", port.display()),
            format!(
                "install the udev rules ({UDEV_RULES}) or `sudo usermod -aG dialout $USER` and log in again"
            ),
        ),
        Err(e) => Finding::fix(
            "port access",
            format!("{}: {e}", port.display()),
            "check the device name (`ls /dev/ttyACM*`) and the cable",
        ),
    }
}

/// The firmware's `version` reply against this checkout's revision.
pub fn check_version(reply: Result<(Vec<String>, String), String>, checkout_rev: &str) -> Finding {
    let (data, closer) = match reply {
        Ok(r) => r,
        Err(e) => {
            return Finding::fix(
                "firmware",
                format!("no answer: {e}"),
                "is the firmware flashed and running? `cargo xtask flash`, then press the black reset button",
            );
        }
    };
    let Some(line) = data.first().filter(|_| closer == "ok") else {
        return Finding::fix(
            "firmware",
            format!("`version` answered {closer:?}, not a version"),
            "the device on this port is not this controller's firmware",
        );
    };
    let rev = line
        .split("(git ")
        .nth(1)
        .and_then(|rest| rest.split([',', ')']).next())
        .unwrap_or("")
        .trim();
    if rev == checkout_rev {
        Finding::ok("firmware", format!("{line} — this checkout"))
    } else {
        Finding::note(
            "firmware",
            format!("{line} — this checkout is {checkout_rev}"),
            "`cargo xtask flash` flashes this checkout's build",
        )
    }
}

fn output_of(program: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(program).args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

fn checkout_rev() -> String {
    Command::new("git")
        .args(["describe", "--always", "--dirty", "--abbrev=10"])
        .current_dir(workspace_root())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_else(|| "unknown".to_owned())
}

fn udev_rule_files() -> Vec<(PathBuf, String)> {
    [
        "/etc/udev/rules.d",
        "/lib/udev/rules.d",
        "/usr/lib/udev/rules.d",
    ]
    .iter()
    .filter_map(|d| std::fs::read_dir(d).ok())
    .flatten()
    .filter_map(Result::ok)
    .map(|e| e.path())
    .filter(|p| p.extension().is_some_and(|x| x == "rules"))
    .filter_map(|p| std::fs::read_to_string(&p).ok().map(|t| (p, t)))
    .collect()
}

/// Every check on this machine.
fn findings(args: &DoctorArgs) -> Vec<Finding> {
    let mut out = Vec::new();
    out.push(check_target(
        &output_of("rustup", &["target", "list", "--installed"]).unwrap_or_default(),
    ));
    out.extend(check_components(
        &output_of("rustup", &["component", "list", "--installed"]).unwrap_or_default(),
    ));
    // flip-link has no --version: that it starts is the check.
    let flip_link = Command::new("flip-link")
        .output()
        .ok()
        .map(|_| "installed".to_owned());
    out.push(check_tool(
        "flip-link",
        flip_link,
        "cargo install flip-link --locked",
        "the firmware's linker; `cargo xtask build` installs it too",
    ));
    let probe_rs = output_of("probe-rs", &["--version"]).map(|v| v.trim().to_owned());
    let have_probe_rs = probe_rs.is_some();
    out.push(check_tool(
        "probe-rs",
        probe_rs,
        "cargo install probe-rs-tools --locked",
        "flashes the board and shows its defmt logs",
    ));
    if cfg!(target_os = "linux") {
        out.push(check_udev(&udev_rule_files()));
    }
    let listing = have_probe_rs.then(|| output_of("probe-rs", &["list"]).unwrap_or_default());
    out.push(check_probes(listing.as_deref()));
    let consoles = find_consoles(Path::new("/sys"));
    out.push(check_consoles(&consoles));
    let port = args.port.clone().or_else(|| consoles.first().cloned());
    if let Some(port) = port {
        let console = crate::serial::Console::open(&port);
        let opened = match &console {
            Ok(_) => Ok(()),
            Err(e) => Err(e
                .downcast_ref::<std::io::Error>()
                .map(|io| std::io::Error::new(io.kind(), io.to_string()))
                .unwrap_or_else(|| std::io::Error::other(format!("{e:#}")))),
        };
        out.push(check_access(&port, opened));
        if let Ok(mut console) = console {
            let reply = console
                .drain(Duration::from_millis(200))
                .and_then(|()| console.command("version", Duration::from_secs(2)))
                .map_err(|e| format!("{e:#}"));
            out.push(check_version(reply, &checkout_rev()));
        }
    }
    out
}

/// Prints `findings` as the report; how many must be fixed.
pub fn print(findings: &[Finding]) -> usize {
    for f in findings {
        let tag = match f.verdict {
            Verdict::Ok => "ok  ",
            Verdict::Fix => "FIX ",
            Verdict::Note => "note",
        };
        println!("{tag} {:<15} {}", f.what, f.detail);
        if let Some(fix) = &f.fix {
            println!("     {:<15} -> {fix}", "");
        }
    }
    findings
        .iter()
        .filter(|f| f.verdict == Verdict::Fix)
        .count()
}

/// Runs `cargo xtask doctor`: exit 1 when something must be fixed.
pub fn run(args: DoctorArgs) -> anyhow::Result<ExitCode> {
    let report = findings(&args);
    let to_fix = print(&report);
    if to_fix == 0 {
        println!("doctor: nothing to fix");
        Ok(ExitCode::SUCCESS)
    } else {
        println!("doctor: {to_fix} thing(s) to fix (see FIX lines)");
        Ok(ExitCode::FAILURE)
    }
}

#[cfg(test)]
mod tests;
