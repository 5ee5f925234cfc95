use super::*;
use crate::executor;

/// A device that answers every line with `ok`.
async fn echo_ok_device(host: Rc<UsbHost>) {
    let mut buf = [0u8; 64];
    loop {
        let n = host.to_device.read(&mut buf).await;
        for _ in buf[..n].iter().filter(|&&b| b == b'\n') {
            host.from_device.write_all(b"ok\r\n").await;
        }
    }
}

#[test]
fn interactive_lines_are_typed_in_order_until_the_input_ends() {
    let host = Rc::new(UsbHost::new(false));
    let (send, lines) = std::sync::mpsc::channel();
    for line in ["status", "# a comment", "wait 100", "goto 1 2"] {
        send.send(line.to_owned()).unwrap();
    }
    drop(send);
    let (h1, h2, h3, stop) = (host.clone(), host.clone(), host.clone(), host.clone());
    let end = executor::run(
        false,
        10_000_000,
        move |spawner| {
            executor::spawn(&spawner, interactive_task(lines, h1));
            executor::spawn(&spawner, terminal_task(h2));
            executor::spawn(&spawner, echo_ok_device(h3));
        },
        move || stop.transcript.borrow().script_done,
    );
    assert_eq!(end, executor::RunEnd::Stopped);
    let transcript = host.transcript.borrow();
    let lines: Vec<&str> = transcript.lines.iter().map(|(_, l)| l.as_str()).collect();
    assert_eq!(lines, ["> status", "ok", "> goto 1 2", "ok"]);
    let goto_at = transcript.lines[2].0;
    assert!(goto_at >= 100_000, "the wait line waited: {goto_at} µs");
}

#[test]
fn a_stalled_terminal_reads_nothing_until_the_stall_ends() {
    let host = Rc::new(UsbHost::new(false));
    let steps =
        crate::script::parse_script("@stall-read 500\n@type-ahead a\nb\nwait 10\nc\n").unwrap();
    let (h1, h2, h3, stop) = (host.clone(), host.clone(), host.clone(), host.clone());
    let end = executor::run(
        false,
        10_000_000,
        move |spawner| {
            let hands = Hands {
                button: Rc::new(ButtonContacts::default()),
                bus: Rc::default(),
                controls: None,
            };
            executor::spawn(&spawner, script_task(steps, h1, hands));
            executor::spawn(&spawner, terminal_task(h2));
            executor::spawn(&spawner, echo_ok_device(h3));
        },
        move || stop.transcript.borrow().script_done,
    );
    assert_eq!(end, executor::RunEnd::Stopped);
    let transcript = host.transcript.borrow();
    let lines: Vec<&str> = transcript.lines.iter().map(|(_, l)| l.as_str()).collect();
    assert_eq!(lines, ["> a", "> b", "ok", "ok", "> c", "ok"]);
    let first_ok = transcript.lines[2].0;
    assert!(
        first_ok >= 500_000,
        "read during the stall at {first_ok} µs"
    );
    assert!(transcript.lines[1].0 < 1_000, "typed during the stall");
    assert!(transcript.unterminated.is_empty());
}
