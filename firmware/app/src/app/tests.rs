extern crate std;

use core::convert::Infallible;
use std::vec::Vec;

use super::*;
use crate::command::CommandLink;
use crate::galvo::{DacSample, DacStream, GalvoLink, Half, Underrun};
use crate::laser_gate::LaserGate;
use crate::sequencer::{LaserSwitch, SettingsStore};
use crate::servo::task::ServoLink;
use crate::status::StatusBoard;

/// A part that says which board it came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Part(u8);

/// Bytes nowhere.
struct Sink;

impl embedded_io_async::ErrorType for Sink {
    type Error = Infallible;
}

impl embedded_io_async::Write for Sink {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        Ok(buf.len())
    }
    async fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

struct TestConsole {
    part: Part,
    rx: &'static [u8],
    tx: Sink,
}

impl Console for TestConsole {
    type Rx = &'static [u8];
    type Tx = Sink;
    type Presence = super::NoHangUp;
    async fn connected(&mut self) -> (&mut &'static [u8], &mut Sink) {
        (&mut self.rx, &mut self.tx)
    }
    fn presence(&self) -> super::NoHangUp {
        super::NoHangUp
    }
}

impl LaserSwitch for Part {
    fn set(&mut self, _power: crate::sequencer::LaserPower) {}
}

impl SettingsStore for Part {
    async fn load(&mut self, _buf: &mut [u8]) -> usize {
        0
    }
    async fn save(&mut self, _record: &[u8]) -> Result<(), &'static str> {
        Ok(())
    }
    async fn load_preset(&mut self, _n: u8) -> Option<crate::domain::PointCm> {
        None
    }
    async fn save_preset(
        &mut self,
        _n: u8,
        _point: Option<crate::domain::PointCm>,
    ) -> Result<(), &'static str> {
        Ok(())
    }
}

impl DacStream for Part {
    fn half_len(&self) -> usize {
        1
    }
    fn set_sample_period(&mut self, _period_s: f64) {}
    fn holds(&self, _sample: DacSample) -> bool {
        false
    }
    async fn write_half(&mut self, _half: Half<'_>) -> Result<(), Underrun> {
        Ok(())
    }
    async fn repeat_half(&mut self) {}
}

impl crate::stepper::StepperDrive for Part {
    fn set_enabled(&mut self, _enabled: bool) {}
    fn set_signals(&mut self, _timing: crate::stepper::DriverSignals) {}
    fn step(&mut self, _step: [bool; 2], _negative: [bool; 2]) {}
    async fn wait_ticks(&mut self, _ticks: u32) {}
    fn restart(&mut self) {}
    fn limits(&mut self) -> [bool; 2] {
        [false; 2]
    }
}

impl crate::pelco::PelcoLine for Sink {
    fn set_baud(&mut self, _baud: u32) {}
}

impl Indicators for Part {
    fn show(&mut self, _leds: Leds) {}
}

impl StopButton for Part {
    async fn pressed(&mut self) {}
}

impl LaserControls for Part {
    fn read(&mut self) -> crate::laser_controls::ControlInputs {
        crate::laser_controls::ControlInputs::default()
    }
    async fn changed(&mut self) {}
    fn set_indicator(&mut self, _on: bool) {}
}

impl Watchdog for Part {
    fn start(&mut self) {}
    fn feed(&mut self) {}
}

/// A board whose parts all carry its number; with or without a galvo DAC
/// (and stepper outputs, laser controls and a PELCO port, which come with
/// it here).
struct TestBoard {
    id: u8,
    has_dac: bool,
}

impl Board for TestBoard {
    type Console = TestConsole;
    type ServoRx = &'static [u8];
    type ServoTx = Sink;
    type Laser = Part;
    type Settings = Part;
    type GalvoDac = Part;
    type Stepper = Part;
    type Indicators = Part;
    type StopButton = Part;
    type Watchdog = Part;
    type LaserControls = Part;
    type PelcoRx = &'static [u8];
    type PelcoTx = Sink;

    fn into_parts(self) -> Parts<Self> {
        let part = Part(self.id);
        Parts {
            console: TestConsole {
                part,
                rx: b"",
                tx: Sink,
            },
            servo_rx: b"",
            servo_tx: Sink,
            laser: part,
            settings: part,
            galvo_dac: self.has_dac.then_some(part),
            stepper: self.has_dac.then_some(part),
            indicators: part,
            stop_button: part,
            watchdog: part,
            laser_controls: self.has_dac.then_some(part),
            pelco: self.has_dac.then_some((&b"pelco"[..], Sink)),
        }
    }
}

/// Records which hook got which board's part, in order.
#[derive(Default)]
struct Spawned(Vec<(&'static str, Part)>);

impl Spawn<TestBoard> for Spawned {
    fn console(&mut self, task: ConsoleTask<TestConsole>) {
        self.0.push(("console", task.port.part));
    }
    fn servo_bus(&mut self, task: ServoBusTask<&'static [u8], Sink>) {
        assert!(task.rx.is_empty());
        self.0.push(("servo bus", Part(u8::MAX)));
    }
    fn sequencer(&mut self, task: SequencerTask<Part, Part>) {
        assert_eq!(task.laser, task.store);
        self.0.push(("sequencer", task.laser));
    }
    fn galvo(&mut self, task: GalvoTask<Part>) {
        self.0.push(("galvo", task.dac));
    }
    fn step_pulses(&mut self, task: crate::stepper::StepPulseTask<Part>) {
        self.0.push(("step pulses", task.drive));
    }
    fn stepper(&mut self, task: crate::stepper::StepperTask) {
        assert_eq!(task.config, crate::stepper::StepperConfig::default());
        self.0.push(("stepper", Part(u8::MAX - 1)));
    }
    fn indicators(&mut self, task: IndicatorTask<Part>) {
        self.0.push(("indicators", task.leds));
    }
    fn stop_button(&mut self, task: StopButtonTask<Part>) {
        self.0.push(("stop button", task.button));
    }
    fn watchdog(&mut self, task: WatchdogTask<Part>) {
        self.0.push(("watchdog", task.dog));
    }
    fn laser_controls(&mut self, task: LaserControlsTask<Part>) {
        self.0.push(("laser controls", task.controls));
    }
    fn pelco(&mut self, task: crate::pelco::PelcoTask<&'static [u8], Sink>) {
        assert_eq!(task.rx, b"pelco");
        self.0.push(("pelco", Part(u8::MAX - 2)));
    }
}

static COMMAND: CommandLink = CommandLink::new();
static SERVO: ServoLink = ServoLink::new();
static GALVO: GalvoLink = GalvoLink::new();
static STATUS: StatusBoard = StatusBoard::new();
static GATE: LaserGate = LaserGate::new();
static STEPPER: crate::stepper::StepperLink = crate::stepper::StepperLink::new();
static CONTROLS: crate::laser_controls::ControlsLink = crate::laser_controls::ControlsLink::new();

fn links() -> Links {
    Links {
        command: &COMMAND,
        servo: &SERVO,
        galvo: &GALVO,
        status: &STATUS,
        gate: &GATE,
        stepper: &STEPPER,
        controls: &CONTROLS,
    }
}

fn wired(board: TestBoard) -> Vec<(&'static str, Part)> {
    let mut spawned = Spawned::default();
    wire(board, links(), &mut spawned);
    spawned.0
}

#[test]
fn every_task_gets_its_part_once_in_dataflow_order() {
    let p = Part(7);
    assert_eq!(
        wired(TestBoard {
            id: 7,
            has_dac: true
        }),
        [
            ("console", p),
            ("servo bus", Part(u8::MAX)),
            ("sequencer", p),
            ("galvo", p),
            ("step pulses", p),
            ("stepper", Part(u8::MAX - 1)),
            ("indicators", p),
            ("stop button", p),
            ("watchdog", p),
            ("laser controls", p),
            ("pelco", Part(u8::MAX - 2)),
        ]
    );
    assert!(
        !GATE.is_permitted(),
        "a board with laser controls starts with the gate forbidden"
    );
}

#[test]
fn a_board_without_a_galvo_dac_steppers_or_pelco_port_runs_none_of_their_tasks() {
    let names: Vec<_> = wired(TestBoard {
        id: 3,
        has_dac: false,
    })
    .into_iter()
    .map(|(name, _)| name)
    .collect();
    assert_eq!(
        names,
        [
            "console",
            "servo bus",
            "sequencer",
            "indicators",
            "stop button",
            "watchdog"
        ]
    );
}

#[test]
fn leds_show_heartbeat_laser_and_fault() {
    let status = StatusBoard::new();
    let beats: Vec<bool> = (0..2 * HEARTBEAT_TICKS)
        .map(|tick| leds_at(&status, tick).heartbeat)
        .collect();
    assert_eq!(beats.iter().filter(|b| **b).count(), 2);
    assert!(beats[0] && beats[HEARTBEAT_TICKS as usize]);
    assert_eq!(leds_at(&status, 1), Leds::default());
    status.update(|s| {
        s.laser_on = true;
        s.faulty_servo = Some(1);
    });
    assert_eq!(
        leds_at(&status, 1),
        Leds {
            heartbeat: false,
            laser: true,
            fault: true
        }
    );
}
