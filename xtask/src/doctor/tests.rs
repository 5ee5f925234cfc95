use laser_sim::on_pty::SimOnPty;
use laser_sim::world::SimOptions;

use super::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("xtask-doctor-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn toolchain_checks_name_the_fix() {
    assert_eq!(
        check_target("x86_64-unknown-linux-gnu\nthumbv7em-none-eabihf\n").verdict,
        Verdict::Ok
    );
    let missing = check_target("x86_64-unknown-linux-gnu\n");
    assert_eq!(missing.verdict, Verdict::Fix);
    assert_eq!(
        missing.fix.as_deref(),
        Some("rustup target add thumbv7em-none-eabihf")
    );
    let components =
        check_components("rustfmt-x86_64-unknown-linux-gnu\nclippy-x86_64-unknown-linux-gnu\n");
    assert_eq!(
        components
            .iter()
            .filter(|f| f.verdict == Verdict::Ok)
            .count(),
        2
    );
    let llvm = components
        .iter()
        .find(|f| f.verdict == Verdict::Fix)
        .unwrap();
    assert_eq!(llvm.fix.as_deref(), Some("rustup component add llvm-tools"));
    let probe_rs = check_tool(
        "probe-rs",
        None,
        "cargo install probe-rs-tools --locked",
        "flashes",
    );
    assert_eq!(probe_rs.verdict, Verdict::Fix);
    assert!(probe_rs.fix.unwrap().contains("probe-rs-tools"));
}

#[test]
fn the_shipped_udev_rules_satisfy_the_check() {
    let path = workspace_root().join(UDEV_RULES);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        check_udev(&[(path.clone(), text.clone())]).verdict,
        Verdict::Ok
    );
    let commented: String = text.lines().map(|l| format!("# {l}\n")).collect();
    assert_eq!(check_udev(&[(path, commented)]).verdict, Verdict::Fix);
    let none = check_udev(&[]);
    assert_eq!(none.verdict, Verdict::Fix);
    assert!(none.fix.unwrap().contains(UDEV_RULES));
}

#[test]
fn no_probe_and_no_board_are_notes_with_a_way_to_check() {
    let no_probe = check_probes(Some("No debug probes were found.\n"));
    assert_eq!(no_probe.verdict, Verdict::Note);
    assert!(no_probe.fix.unwrap().contains("probe-rs list"));
    let probe = check_probes(Some(
        "The following debug probes were found:\n[0]: STLink V2-1 -- 0483:374b:066DFF (ST-LINK)\n",
    ));
    assert_eq!(probe.verdict, Verdict::Ok);
    assert!(probe.detail.contains("STLink"));
    assert_eq!(check_consoles(&[]).verdict, Verdict::Note);
}

#[test]
fn consoles_are_found_by_their_usb_ids() {
    let sys = scratch("sys");
    for (tty, vendor, product) in [
        ("ttyACM0", "0483", "374b"),
        ("ttyACM1", "c0de", "cafe"),
        ("ttyS0", "c0de", "cafe"),
    ] {
        let usb = sys.join("devices").join(tty);
        std::fs::create_dir_all(usb.join("intf")).unwrap();
        std::fs::write(usb.join("idVendor"), format!("{vendor}\n")).unwrap();
        std::fs::write(usb.join("idProduct"), format!("{product}\n")).unwrap();
        let class = sys.join("class/tty").join(tty);
        std::fs::create_dir_all(&class).unwrap();
        std::os::unix::fs::symlink(usb.join("intf"), class.join("device")).unwrap();
    }
    let found = find_consoles(&sys);
    std::fs::remove_dir_all(&sys).ok();
    assert_eq!(found, vec![PathBuf::from("/dev/ttyACM1")]);
}

#[test]
fn version_replies_are_judged_against_the_checkout() {
    let line = "laser-pointer 0.1.0 (git abc1234567, release build for thumbv7em-none-eabihf)";
    let ok = check_version(Ok((vec![line.to_owned()], "ok".to_owned())), "abc1234567");
    assert_eq!(ok.verdict, Verdict::Ok);
    let other = check_version(Ok((vec![line.to_owned()], "ok".to_owned())), "def7654321");
    assert_eq!(other.verdict, Verdict::Note);
    assert!(other.fix.unwrap().contains("cargo xtask flash"));
    let silent = check_version(Err("no reply".to_owned()), "x");
    assert_eq!(silent.verdict, Verdict::Fix);
    let wrong = check_version(Ok((vec![], "error: unknown command".to_owned())), "x");
    assert_eq!(wrong.verdict, Verdict::Fix);
}

#[test]
fn a_port_without_permission_says_how_to_get_it() {
    let denied = check_access(
        Path::new("/dev/ttyACM0"),
        Err(std::io::Error::from(std::io::ErrorKind::PermissionDenied)),
    );
    assert_eq!(denied.verdict, Verdict::Fix);
    assert!(denied.fix.unwrap().contains("dialout"));
}

/// The whole `--port` path against the simulator's console on a PTY: the
/// port opens, `version` is answered, and the reply names a build.
#[test]
fn the_firmware_check_talks_to_a_simulated_board() {
    let dir = scratch("pty");
    let sim = SimOnPty::start(
        dir.join("console"),
        SimOptions {
            max_time_ms: 60_000,
            ..SimOptions::default()
        },
    )
    .expect("the simulator starts");
    let report = findings(&DoctorArgs {
        port: Some(sim.link.clone()),
    });
    sim.finish();
    std::fs::remove_dir_all(&dir).ok();
    let access = report
        .iter()
        .find(|f| f.what == "port access")
        .expect("access checked");
    assert_eq!(access.verdict, Verdict::Ok, "{access:?}");
    let firmware = report
        .iter()
        .find(|f| f.what == "firmware")
        .expect("firmware checked");
    assert_ne!(firmware.verdict, Verdict::Fix, "{firmware:?}");
    assert!(
        firmware.detail.starts_with("laser-pointer "),
        "{firmware:?}"
    );
}
