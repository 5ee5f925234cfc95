//! The servo-bus set-up: the simulated servos' side (re-ID by write data,
//! two servos with one id colliding, unplugged cables), and the firmware's
//! servo task running its set-up jobs against them in virtual time.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use fashionstar::testing::frame;
use fashionstar::{DecodeError, Request, Response, ResponseDecoder, SetAngle, WriteResult};
use laser_app::servo::task::{
    BusEnd, BusJob, BusReport, ServoBus, ServoBusConfig, ServoLink, ServoOutcome, ServoRequest,
};

use super::*;
use crate::executor::{self, RunEnd};
use crate::recorder::Recording;
use crate::servo_port::{BusFaults, PortHandle, SimServoPort};

const MS: u64 = 1000;

fn decode_all(answers: &[(u64, Vec<u8>)]) -> Vec<Result<Response, DecodeError>> {
    let mut d = ResponseDecoder::new();
    let bytes: Vec<u8> = answers.iter().flat_map(|(_, b)| b.clone()).collect();
    d.decode(&bytes).collect()
}

#[test]
fn write_data_to_address_34_re_ids_the_servo_answering_under_its_old_id() {
    let mut bus = SimServoBus::new(&[0], 1.0);
    let answers = bus.receive(MS, &frame(&Request::set_servo_id(0, 7)));
    assert_eq!(
        decode_all(&answers),
        [Ok(Response::WriteData(WriteResult {
            id: 0,
            address: 34,
            result: 1
        }))]
    );
    assert_eq!(bus.servo_in_slot(0).map(SimServo::id), Some(7));
    assert!(
        bus.receive(2 * MS, &frame(&Request::Ping { id: 0 }))
            .is_empty()
    );
    assert_eq!(
        decode_all(&bus.receive(3 * MS, &frame(&Request::Ping { id: 7 }))),
        [Ok(Response::Ping { id: 7 })]
    );
    // 255 is the broadcast address: refused, nothing changes.
    let answers = bus.receive(4 * MS, &frame(&Request::set_servo_id(7, 255)));
    assert_eq!(
        decode_all(&answers),
        [Ok(Response::WriteData(WriteResult {
            id: 7,
            address: 34,
            result: 0
        }))]
    );
    assert_eq!(bus.servo_in_slot(0).map(SimServo::id), Some(7));
}

#[test]
fn two_servos_with_one_id_collide_and_an_unplugged_one_is_deaf() {
    let mut bus = SimServoBus::new(&[0, 0], 1.0);
    // Both answer the ping at once: one garbled frame, checksum bad.
    let answers = bus.receive(MS, &frame(&Request::Ping { id: 0 }));
    assert_eq!(answers.len(), 1);
    assert!(
        matches!(
            decode_all(&answers)[..],
            [Err(DecodeError::BadChecksum { code: 1, .. })]
        ),
        "{answers:?}"
    );
    // Both obey a move addressed to id 0.
    let set = Request::SetAngle(SetAngle {
        id: 0,
        angle_tenths_deg: 300,
        interval_ms: 100,
        power_mw: 0,
    });
    bus.receive(2 * MS, &frame(&set));
    let at = |bus: &SimServoBus, slot| bus.servo_in_slot(slot).unwrap().angle_tenths(500 * MS);
    assert_eq!((at(&bus, 0), at(&bus, 1)), (300, 300));
    // Unplugged, the first neither moves nor answers; the second alone
    // answers cleanly.
    assert!(bus.set_plugged(0, false));
    assert!(!bus.set_plugged(2, false), "no third slot");
    let back = Request::SetAngle(SetAngle {
        angle_tenths_deg: -100,
        ..match set {
            Request::SetAngle(s) => s,
            _ => unreachable!(),
        }
    });
    bus.receive(600 * MS, &frame(&back));
    assert_eq!((at(&bus, 0), at(&bus, 1)), (300, 300));
    let at_end = |bus: &SimServoBus, slot| bus.servo_in_slot(slot).unwrap().angle_tenths(900 * MS);
    assert_eq!((at_end(&bus, 0), at_end(&bus, 1)), (300, -100));
    assert_eq!(
        decode_all(&bus.receive(1000 * MS, &frame(&Request::Ping { id: 0 }))),
        [Ok(Response::Ping { id: 0 })]
    );
}

/// Before a job: plug (`true`) or unplug the cable of a slot.
type Cable = Option<(usize, bool)>;

/// Runs the firmware's servo task on `bus` and has it do each job in turn
/// (after its cable step), in one run of virtual time; returns what each
/// reported and when it ended, µs.
fn run_jobs(
    bus: &Rc<RefCell<SimServoBus>>,
    jobs: &[(Cable, BusJob)],
) -> Vec<(Vec<BusReport>, u64)> {
    let port = Rc::new(SimServoPort::new(
        bus.clone(),
        Rc::new(RefCell::new(Recording::default())),
        BusFaults::default(),
        1,
    ));
    let link: &'static ServoLink = Box::leak(Box::new(ServoLink::new()));
    let results = Rc::new(RefCell::new(Vec::new()));
    let done = Rc::new(Cell::new(false));
    let (r, d, b, jobs) = (results.clone(), done.clone(), bus.clone(), jobs.to_vec());
    let end = executor::run(
        false,
        60_000_000,
        move |spawner| {
            let mut servo_bus = ServoBus::new(
                PortHandle(port.clone()),
                PortHandle(port),
                ServoBusConfig::default(),
            );
            executor::spawn(&spawner, async move { servo_bus.run(link).await });
            executor::spawn(&spawner, async move {
                for (seq, (cable, job)) in (1..).zip(jobs) {
                    if let Some((slot, plugged)) = cable {
                        b.borrow_mut().set_plugged(slot, plugged);
                    }
                    link.requests.send(ServoRequest::Setup { seq, job }).await;
                    let mut reports = Vec::new();
                    loop {
                        match link.outcomes.receive().await {
                            ServoOutcome::Bus { seq: s, report } if s == seq => {
                                reports.push(report);
                                if let BusReport::Done(_) = report {
                                    break;
                                }
                            }
                            other => panic!("unexpected {other:?}"),
                        }
                    }
                    r.borrow_mut().push((reports, crate::clock::now_us()));
                }
                d.set(true);
            });
        },
        move || done.get(),
    );
    assert_eq!(end, RunEnd::Stopped);
    results.borrow().clone()
}

/// One job on `bus`: what it reported, when it ended (µs).
fn run_job(bus: &Rc<RefCell<SimServoBus>>, job: BusJob) -> (Vec<BusReport>, u64) {
    run_jobs(bus, &[(None, job)]).remove(0)
}

fn servo_line(report: &BusReport) -> Option<(u8, i32)> {
    match report {
        BusReport::Servo(r) => Some((r.id, r.angle_tenths)),
        _ => None,
    }
}

#[test]
fn a_scan_finds_every_servo_with_its_monitor_data_in_under_3_s() {
    let bus = Rc::new(RefCell::new(SimServoBus::from_servos(vec![
        SimServo::new(0).with_angle_deg(12.3),
        SimServo::new(9),
    ])));
    let (reports, t_us) = run_job(&bus, BusJob::Scan);
    let lines: Vec<_> = reports.iter().filter_map(servo_line).collect();
    assert_eq!(lines, [(0, 123), (9, 0)]);
    let BusReport::Servo(r) = reports[0] else {
        panic!("{reports:?}")
    };
    assert_eq!(
        (r.voltage_mv, r.temperature_raw),
        (SUPPLY_MV, TEMPERATURE_RAW)
    );
    assert_eq!(
        reports.last(),
        Some(&BusReport::Done(BusEnd::Scanned {
            answering: 2,
            collisions: 0
        }))
    );
    // 253 silent ids at the 10 ms scan timeout.
    assert!((2_530_000..3_000_000).contains(&t_us), "{t_us} µs");
}

#[test]
fn duplicate_ids_are_reported_and_re_id_is_refused_until_one_is_alone() {
    let bus = Rc::new(RefCell::new(SimServoBus::new(&[0, 0], 1.0)));
    let set_id = BusJob::SetId { id: 0, new_id: 1 };
    let runs = run_jobs(
        &bus,
        &[
            (None, BusJob::Scan),
            (None, set_id),
            // The first unplugged: the second is alone and takes id 1.
            (Some((0, false)), set_id),
            // Plugged back: both answer a scan.
            (Some((0, true)), BusJob::Scan),
        ],
    );
    assert_eq!(
        runs[0].0,
        [
            BusReport::Collision { id: 0 },
            BusReport::Done(BusEnd::Scanned {
                answering: 0,
                collisions: 1
            })
        ]
    );
    assert_eq!(
        runs[1].0.last(),
        Some(&BusReport::Done(BusEnd::NotAlone {
            answering: 0,
            collisions: 1
        }))
    );
    assert_eq!(
        runs[2].0.last(),
        Some(&BusReport::Done(BusEnd::IdChanged { id: 0, new_id: 1 }))
    );
    assert_eq!(
        runs[2].0.iter().filter_map(servo_line).collect::<Vec<_>>(),
        [(0, 0), (1, 0)],
        "found alone as 0, then answering as 1"
    );
    assert_eq!(
        runs[3].0.iter().filter_map(servo_line).collect::<Vec<_>>(),
        [(0, 0), (1, 0)]
    );
    let bus = bus.borrow();
    let ids = [0, 1].map(|slot| bus.servo_in_slot(slot).unwrap().id());
    assert_eq!(ids, [0, 1], "the second re-IDed, the first not");
}

#[test]
fn re_id_is_written_only_when_alone() {
    let bus = Rc::new(RefCell::new(SimServoBus::new(&[0, 0], 1.0)));
    let (reports, _) = run_job(&bus, BusJob::SetId { id: 0, new_id: 1 });
    assert!(matches!(
        reports.last(),
        Some(BusReport::Done(BusEnd::NotAlone { .. }))
    ));
    let bus = bus.borrow();
    assert_eq!(
        [0, 1].map(|slot| bus.servo_in_slot(slot).unwrap().id()),
        [0, 0],
        "nothing written"
    );
}

#[test]
fn re_id_of_an_absent_servo_ping_and_angle_read() {
    let bus = Rc::new(RefCell::new(SimServoBus::from_servos(vec![
        SimServo::new(3).with_angle_deg(-4.5),
    ])));
    let runs = run_jobs(
        &bus,
        &[
            (None, BusJob::SetId { id: 0, new_id: 1 }),
            (None, BusJob::Ping { id: 3 }),
            (None, BusJob::Ping { id: 4 }),
            (None, BusJob::ReadAngle { id: 3 }),
        ],
    );
    assert_eq!(
        runs[0].0.last(),
        Some(&BusReport::Done(BusEnd::NoAnswer { id: 0 }))
    );
    assert_eq!(bus.borrow().servo_in_slot(0).map(SimServo::id), Some(3));
    assert_eq!(
        runs[1].0.iter().filter_map(servo_line).collect::<Vec<_>>(),
        [(3, -45)]
    );
    assert_eq!(runs[1].0.last(), Some(&BusReport::Done(BusEnd::Answered)));
    assert_eq!(runs[2].0, [BusReport::Done(BusEnd::NoAnswer { id: 4 })]);
    assert_eq!(
        runs[3].0,
        [BusReport::Done(BusEnd::Angle { id: 3, tenths: -45 })]
    );
}
