//! Tests of the simulated servos, driven through real request frames and
//! checked through real response frames decoded by the firmware decoder.

use fashionstar::testing::frame;
use fashionstar::{
    DecodeError, ReadData, Request, Response, ResponseDecoder, SetAngle, SetAngleByInterval,
    SetAngleByVelocity, SyncEntries,
};
use proptest::prelude::*;

use super::*;

const MS: u64 = 1000;

fn set(id: u8, angle_tenths_deg: i16, interval_ms: u16) -> Request {
    Request::SetAngle(SetAngle {
        id,
        angle_tenths_deg,
        interval_ms,
        power_mw: 0,
    })
}

/// Decodes the answers with the firmware's decoder; every byte must belong
/// to a valid frame.
fn decode(answers: &[(u64, Vec<u8>)]) -> Vec<Response> {
    let mut d = ResponseDecoder::new();
    let bytes: Vec<u8> = answers
        .iter()
        .flat_map(|(_, b)| b.iter().copied())
        .collect();
    let events: Vec<Result<Response, DecodeError>> = d.decode(&bytes).collect();
    assert_eq!(d.buffered(), 0);
    events.into_iter().map(Result::unwrap).collect()
}

/// First 1 ms sample from `from_us` on where servo `id` reports `tenths`.
fn first_at(bus: &SimServoBus, id: u8, tenths: i16, from_us: u64) -> u64 {
    (0..10_000)
        .map(|k| from_us + k * MS)
        .find(|&t| bus.angle_tenths_at(id, t) == Some(tenths))
        .unwrap()
}

#[test]
fn wire_time() {
    assert_eq!(wire_time_us(0), 0);
    assert_eq!(BYTE_TIME_US, 87); // 86.8 µs rounded up
    assert_eq!(wire_time_us(12), 1044); // a set-angle frame ≈ 1.04 ms
    assert_eq!(wire_time_us(22), 1914);
}

#[test]
fn commanded_move_reaches_target_on_time() {
    let mut bus = SimServoBus::new(&[0, 1], 1.0);
    let t0 = 10 * MS;
    assert!(bus.receive(t0, &frame(&set(0, 900, 1000))).is_empty());
    let arrived = first_at(&bus, 0, 900, t0);
    assert!(arrived.abs_diff(t0 + 1000 * MS) <= MS, "{arrived}");
    assert_eq!(bus.angle_tenths_at(0, t0 + 999 * MS), Some(899));
    assert_eq!(bus.angle_tenths_at(0, t0 + 60_000 * MS), Some(900));
    assert!(!bus.servo(0).unwrap().is_moving(t0 + 1000 * MS));
    assert_eq!(bus.servo(0).unwrap().arrival_us(), t0 + 1000 * MS);
    // Linear in time: halfway at half time.
    assert_eq!(bus.angle_deg(0, t0 + 500 * MS), Some(45.0));
    // The other servo did not move.
    assert_eq!(bus.angle_deg(1, t0 + 500 * MS), Some(0.0));
    assert_eq!(bus.angle_deg(7, t0), None);
}

#[test]
fn reported_angle_is_rounded_to_a_tenth() {
    let mut bus = SimServoBus::from_servos(vec![SimServo::new(0).with_angle_deg(12.36)]);
    assert_eq!(bus.angle_tenths_at(0, 0), Some(124));
    assert_eq!(bus.servo(0).unwrap().angle_deg(0), 12.36);
    bus.receive(0, &frame(&set(0, -1000, 700)));
    for t in (0..800 * MS).step_by(7919) {
        let exact = bus.angle_deg(0, t).unwrap();
        assert_eq!(
            bus.angle_tenths_at(0, t),
            Some((exact * 10.0).round() as i16)
        );
    }
    let answers = bus.receive(350 * MS, &frame(&Request::QueryAngle { id: 0 }));
    let exact = bus.angle_deg(0, 350 * MS).unwrap();
    assert_eq!(
        decode(&answers),
        [Response::Angle {
            id: 0,
            angle_tenths_deg: (exact * 10.0).round() as i16
        }]
    );
}

#[test]
fn targets_are_clamped_to_the_servo_range() {
    let mut bus = SimServoBus::new(&[0], 1.0);
    bus.receive(0, &frame(&set(0, 2500, 0)));
    assert_eq!(bus.angle_tenths_at(0, 0), Some(1800));
    bus.receive(MS, &frame(&set(0, i16::MIN, 10)));
    assert_eq!(bus.angle_tenths_at(0, 20 * MS), Some(-1800));
    assert_eq!(bus.servo(0).unwrap().target_tenths(), -1800);
}

#[test]
fn velocity_command_moves_at_the_commanded_speed() {
    let mut bus = SimServoBus::new(&[1], 1.0);
    let r = Request::SetAngleByVelocity(SetAngleByVelocity {
        id: 1,
        angle_tenths_deg: 500,
        velocity_tenths_deg_s: 1000,
        t_acc_ms: 20,
        t_dec_ms: 20,
        power_mw: 0,
    });
    bus.receive(0, &frame(&r));
    // 50° at 100 °/s plus half of the two 20 ms ramps.
    assert_eq!(bus.servo(1).unwrap().arrival_us(), 520 * MS);
    assert_eq!(bus.angle_deg(1, 520 * MS), Some(50.0));
    assert!(bus.angle_deg(1, 519 * MS).unwrap() < 50.0);
    // Reported at the target once less than 0.05° is left: 4.5 ms early
    // on the 20 ms deceleration ramp (0.5 · 100 °/s · t² / 20 ms = 0.05°).
    let reported = first_at(&bus, 1, 500, 0);
    assert!(reported.abs_diff(516 * MS) <= MS, "{reported}");
    let a = bus.angle_deg(1, 200 * MS).unwrap();
    let b = bus.angle_deg(1, 300 * MS).unwrap();
    assert!(((b - a) / 0.1 - 100.0).abs() < 1e-9);
    // Velocity 0 is taken as the SDK's minimum of 1 °/s.
    let mut bus = SimServoBus::new(&[1], 1.0);
    let r = Request::SetAngleByVelocity(SetAngleByVelocity {
        id: 1,
        angle_tenths_deg: 10,
        velocity_tenths_deg_s: 0,
        t_acc_ms: 0,
        t_dec_ms: 0,
        power_mw: 0,
    });
    bus.receive(0, &frame(&r));
    assert_eq!(bus.servo(1).unwrap().arrival_us(), 1000 * MS);
}

#[test]
fn interval_command_with_ramps_arrives_on_time() {
    let mut bus = SimServoBus::new(&[0], 1.0);
    let r = Request::SetAngleByInterval(SetAngleByInterval {
        id: 0,
        angle_tenths_deg: -600,
        interval_ms: 400,
        t_acc_ms: 100,
        t_dec_ms: 100,
        power_mw: 0,
    });
    bus.receive(5 * MS, &frame(&r));
    assert_eq!(bus.angle_deg(0, 205 * MS), Some(-30.0));
    assert_eq!(bus.servo(0).unwrap().arrival_us(), 405 * MS);
    assert_eq!(bus.angle_deg(0, 405 * MS), Some(-60.0));
    assert!(bus.angle_deg(0, 404 * MS).unwrap() > -60.0);
    // On the slow final approach the report reaches -60.0° a few ms early.
    let reported = first_at(&bus, 0, -600, 5 * MS);
    assert!((395 * MS..=405 * MS).contains(&reported), "{reported}");
}

#[test]
fn slow_factor_stretches_moves() {
    let mut bus = SimServoBus::new(&[0, 1], 2.5);
    bus.receive(0, &frame(&set(0, 300, 400)));
    let arrived = first_at(&bus, 0, 300, 0);
    assert!(arrived.abs_diff(1000 * MS) <= MS, "{arrived}");
    bus.set_slow_factor(1.0);
    bus.receive(2000 * MS, &frame(&set(0, 0, 400)));
    assert_eq!(bus.servo(0).unwrap().arrival_us(), 2400 * MS);
    assert_eq!(bus.servo(1).unwrap().slow_factor(), 1.0);
    let mut s = SimServo::new(3);
    s.set_slow_factor(f64::NAN);
    assert_eq!(s.slow_factor(), 1.0);
}

#[test]
fn sync_command_moves_both_servos_together() {
    let mut bus = SimServoBus::new(&[0, 1], 1.0);
    let r = Request::sync_set_angle_pair(
        SetAngle {
            id: 0,
            angle_tenths_deg: 450,
            interval_ms: 300,
            power_mw: 0,
        },
        SetAngle {
            id: 1,
            angle_tenths_deg: -200,
            interval_ms: 300,
            power_mw: 0,
        },
    );
    let bytes = frame(&r);
    assert_eq!(bytes.len(), 22);
    assert!(bus.receive(MS, &bytes).is_empty());
    assert_eq!(bus.servo(0).unwrap().arrival_us(), 301 * MS);
    assert_eq!(bus.servo(1).unwrap().arrival_us(), 301 * MS);
    assert_eq!(bus.angle_tenths_at(0, 151 * MS), Some(225));
    assert_eq!(bus.angle_tenths_at(1, 151 * MS), Some(-100));
    assert_eq!(bus.angle_tenths_at(0, 301 * MS), Some(450));
    assert_eq!(bus.angle_tenths_at(1, 301 * MS), Some(-200));

    // The velocity and interval variants too, for the addressed ids only.
    let v = SetAngleByVelocity {
        id: 1,
        angle_tenths_deg: 0,
        velocity_tenths_deg_s: 2000,
        t_acc_ms: 0,
        t_dec_ms: 0,
        power_mw: 0,
    };
    let r = Request::SyncSetAngleByVelocity(SyncEntries::from_slice(&[v]).unwrap());
    bus.receive(1000 * MS, &frame(&r));
    assert_eq!(bus.servo(1).unwrap().arrival_us(), 1100 * MS);
    assert_eq!(bus.servo(0).unwrap().target_tenths(), 450);
    let i = SetAngleByInterval {
        id: 0,
        angle_tenths_deg: 0,
        interval_ms: 50,
        t_acc_ms: 20,
        t_dec_ms: 20,
        power_mw: 0,
    };
    let r = Request::SyncSetAngleByInterval(SyncEntries::from_slice(&[i]).unwrap());
    bus.receive(2000 * MS, &frame(&r));
    assert_eq!(bus.servo(0).unwrap().arrival_us(), 2050 * MS);
}

#[test]
fn new_command_starts_from_where_the_servo_is() {
    let mut bus = SimServoBus::new(&[0], 1.0);
    bus.receive(0, &frame(&set(0, 900, 1000)));
    bus.receive(500 * MS, &frame(&set(0, 0, 1000)));
    assert_eq!(bus.angle_deg(0, 500 * MS), Some(45.0));
    assert_eq!(bus.angle_deg(0, 1000 * MS), Some(22.5));
    // Damping stops it where it is.
    bus.receive(
        1000 * MS,
        &frame(&Request::Damping {
            id: 0,
            power_mw: 500,
        }),
    );
    assert_eq!(bus.angle_deg(0, 3000 * MS), Some(22.5));
}

#[test]
fn silent_servo_answers_nothing_but_still_moves() {
    let mut bus = SimServoBus::new(&[0, 1], 1.0);
    bus.set_silent(1, true);
    assert!(bus.servo(1).unwrap().is_silent());
    assert!(bus.receive(0, &frame(&Request::Ping { id: 1 })).is_empty());
    assert!(
        bus.receive(MS, &frame(&Request::QueryAngle { id: 1 }))
            .is_empty()
    );
    assert_eq!(
        decode(&bus.receive(2 * MS, &frame(&Request::Ping { id: 0 }))),
        [Response::Ping { id: 0 }]
    );
    bus.receive(3 * MS, &frame(&set(1, 100, 0)));
    assert_eq!(bus.angle_tenths_at(1, 3 * MS), Some(100));
    bus.set_silent(1, false);
    assert_eq!(
        decode(&bus.receive(4 * MS, &frame(&Request::Ping { id: 1 }))),
        [Response::Ping { id: 1 }]
    );
}

#[test]
fn answers_parse_with_the_firmware_decoder() {
    let mut bus = SimServoBus::new(&[0, 1], 1.0);
    bus.receive(0, &frame(&set(1, 900, 1000)));
    let t = 500 * MS;
    let answers = bus.receive(t, &frame(&Request::QueryMonitor { id: 1 }));
    let [Response::Monitor(m)] = decode(&answers)[..] else {
        panic!("{answers:?}");
    };
    assert_eq!(
        (m.id, m.voltage_mv, m.temperature_raw),
        (1, SUPPLY_MV, TEMPERATURE_RAW)
    );
    assert_eq!((m.angle_tenths_deg, m.status, m.turns), (450, 1, 0));
    assert_eq!((m.current_ma, m.power_mw), (MOVING_CURRENT_MA, 1110));
    let answers = bus.receive(2000 * MS, &frame(&Request::QueryMonitor { id: 1 }));
    let [Response::Monitor(m)] = decode(&answers)[..] else {
        panic!("{answers:?}");
    };
    assert_eq!((m.status, m.current_ma), (0, IDLE_CURRENT_MA));

    let read = |bus: &mut SimServoBus, address| {
        decode(&bus.receive(3000 * MS, &frame(&Request::ReadData { id: 0, address })))
    };
    let expect = |address, data: &[u8]| {
        vec![Response::ReadData(ReadData {
            id: 0,
            address,
            data: heapless::Vec::from_slice(data).unwrap(),
        })]
    };
    assert_eq!(read(&mut bus, 1), expect(1, &SUPPLY_MV.to_le_bytes()));
    assert_eq!(read(&mut bus, 4), expect(4, &TEMPERATURE_RAW.to_le_bytes()));
    assert_eq!(read(&mut bus, 5), expect(5, &[0]));
    assert_eq!(read(&mut bus, 34), expect(34, &[0]));
    assert_eq!(read(&mut bus, 99), vec![]);
    // Motion commands and unknown ids are not answered.
    assert!(bus.receive(4000 * MS, &frame(&set(0, 0, 0))).is_empty());
    assert!(
        bus.receive(4000 * MS, &frame(&Request::Ping { id: 9 }))
            .is_empty()
    );
}

#[test]
fn answer_timing_follows_the_wire() {
    let mut bus = SimServoBus::new(&[0, 1], 1.0);
    let ping = frame(&Request::Ping { id: 0 });
    let t = 50 * MS;
    let answers = bus.receive(t, &ping);
    assert_eq!(answers.len(), 1);
    assert_eq!(answers[0].0, t + PROCESSING_DELAY_US);
    // Two queries back to back in one chunk: the first ended one frame
    // earlier, and the second answer waits for the line.
    let mut both = frame(&Request::QueryAngle { id: 1 });
    both.extend(frame(&Request::QueryMonitor { id: 0 }));
    let t = 100 * MS;
    let answers = bus.receive(t, &both);
    assert_eq!(answers.len(), 2);
    let first_end = t - wire_time_us(6);
    assert_eq!(answers[0].0, first_end + PROCESSING_DELAY_US);
    assert_eq!(
        answers[1].0,
        answers[0].0 + wire_time_us(answers[0].1.len())
    );
    // The log has every frame with its start time.
    let log = bus.take_frames();
    assert_eq!(log.len(), 6);
    assert_eq!(
        log[0],
        BusFrame {
            t_us: 50 * MS - wire_time_us(6),
            direction: BusDirection::Tx,
            bytes: ping.clone()
        }
    );
    assert_eq!(log[1].direction, BusDirection::Rx);
    assert_eq!(log[1].t_us, 50 * MS + PROCESSING_DELAY_US);
    assert!(bus.frames().is_empty());
}

#[test]
fn corrupted_request_is_ignored_and_the_next_one_works() {
    let mut bus = SimServoBus::new(&[0], 1.0);
    let mut bad = frame(&set(0, 900, 0));
    bad[6] ^= 0x40;
    assert!(bus.receive(0, &bad).is_empty());
    assert_eq!(bus.angle_tenths_at(0, MS), Some(0));
    assert_eq!(bus.decode_errors(), 1);
    let answers = bus.receive(MS, &frame(&Request::Ping { id: 0 }));
    assert_eq!(decode(&answers), [Response::Ping { id: 0 }]);
}

fn any_request() -> impl Strategy<Value = Request> {
    let id = 0u8..3;
    prop_oneof![
        id.clone().prop_map(|id| Request::Ping { id }),
        id.clone().prop_map(|id| Request::QueryAngle { id }),
        id.clone().prop_map(|id| Request::QueryMonitor { id }),
        (id.clone(), 0u8..8).prop_map(|(id, address)| Request::ReadData { id, address }),
        (id.clone(), any::<i16>(), 0u16..2000).prop_map(|(id, a, i)| set(id, a, i)),
        (id.clone(), any::<i16>(), 0u16..8000, 0u16..300, 0u16..300).prop_map(
            |(id, a, v, ta, td)| {
                Request::SetAngleByVelocity(SetAngleByVelocity {
                    id,
                    angle_tenths_deg: a,
                    velocity_tenths_deg_s: v,
                    t_acc_ms: ta,
                    t_dec_ms: td,
                    power_mw: 0,
                })
            }
        ),
        (any::<i16>(), any::<i16>(), 0u16..2000).prop_map(
            |(a, b, i)| Request::sync_set_angle_pair(
                SetAngle {
                    id: 0,
                    angle_tenths_deg: a,
                    interval_ms: i,
                    power_mw: 0
                },
                SetAngle {
                    id: 1,
                    angle_tenths_deg: b,
                    interval_ms: i,
                    power_mw: 0
                },
            )
        ),
    ]
}

/// Delivers `stream` (starting on the wire at 0, bytes back to back) in
/// chunks of the given sizes, each at the time its last byte arrived.
fn deliver(bus: &mut SimServoBus, stream: &[u8], sizes: &[usize]) -> Vec<(u64, Vec<u8>)> {
    let mut answers = Vec::new();
    let mut at = 0;
    let mut sizes = sizes.iter().cycle();
    while at < stream.len() {
        let n = (*sizes.next().unwrap()).clamp(1, stream.len() - at);
        at += n;
        answers.extend(bus.receive(wire_time_us(at), &stream[at - n..at]));
    }
    answers
}

proptest! {
    /// Chunking of the request bytes changes neither the answers nor the
    /// servos' motion.
    #[test]
    fn chunking_does_not_matter(
        requests in prop::collection::vec(any_request(), 1..12),
        sizes in prop::collection::vec(1usize..30, 1..6),
    ) {
        let stream: Vec<u8> = requests.iter().flat_map(frame).collect();
        let mut whole = SimServoBus::new(&[0, 1, 2], 1.0);
        let mut split = SimServoBus::new(&[0, 1, 2], 1.0);
        let a = deliver(&mut whole, &stream, &[stream.len()]);
        let b = deliver(&mut split, &stream, &sizes);
        prop_assert_eq!(&a, &b);
        // Every answer is a valid frame answering one of the requests.
        for response in decode(&a) {
            prop_assert!(requests.iter().any(|r| response.answers(r)));
        }
        let end = wire_time_us(stream.len());
        for id in 0..3 {
            for t in [end / 2, end, end + 500 * MS, end + 10_000 * MS] {
                let x = whole.angle_deg(id, t).unwrap();
                prop_assert_eq!(x, split.angle_deg(id, t).unwrap());
                prop_assert!(x.abs() <= 180.0);
            }
        }
        prop_assert_eq!(whole.decode_errors(), 0);
    }

    /// Random bytes never panic and any answer is a valid frame.
    #[test]
    fn random_bytes_are_harmless(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        let mut bus = SimServoBus::new(&[0, 1], 1.0);
        let answers = bus.receive(1_000_000, &bytes);
        let _ = decode(&answers);
        for id in 0..2 {
            prop_assert!(bus.angle_deg(id, 100_000_000).unwrap().abs() <= 180.0);
        }
    }
}
