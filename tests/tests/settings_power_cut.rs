//! Settings survive power loss: the settings store (the code the target
//! runs) on a simulated NOR flash that loses power at every program/erase
//! step of a `save` — cleanly between steps, or tearing the step (a partly
//! programmed word, a partly erased sector). After every cut, a boot loads
//! exactly the old or the new record, never nothing or garbage, and the
//! store takes the next save. Presets (items of the same map) likewise:
//! a cut while a preset is set or cleared boots the old or the new preset,
//! the settings record and the other presets untouched.

use embassy_futures::block_on;
use embedded_storage_async::nor_flash::{NorFlash, ReadNorFlash};
use laser_app::domain::PointCm;
use laser_app::settings::store::{FlashSettingsStore, SettingsStore};
use laser_app::settings::{RECORD_LEN, Settings};
use laser_sim::flash::{PowerCut, SimFlash, Tear};
use sequential_storage::map::MapConfig;

/// The F407's 128 KiB sectors scaled by 1/64, so a handful of saves fills
/// a sector and the sector hand-over is cut too (a sector holds two
/// records of 628 bytes; 1/128 held only one once the stepper parameters
/// came).
const SECTOR: usize = 2048;
type Flash = SimFlash<SECTOR>;
/// Sectors 10 and 11 (0x080C_0000, 0x080E_0000), scaled.
const BASE: u32 = 0x000C_0000 / 64;

fn store(flash: Flash) -> FlashSettingsStore<Flash> {
    FlashSettingsStore::new(
        flash,
        const { MapConfig::new(BASE..BASE + 2 * SECTOR as u32) },
    )
}

/// Boots from `image` and returns the record it loads (empty: none).
fn boot(image: Vec<u8>) -> Vec<u8> {
    let mut s = store(Flash::from_image(BASE, image));
    let mut record = vec![0u8; RECORD_LEN];
    let n = block_on(s.load(&mut record));
    record.truncate(n);
    record
}

/// Distinct, valid settings number `i`.
fn settings(i: u32) -> Settings {
    Settings {
        dwell_ms: 100.0 + f64::from(i),
        oq_cm: 20.0 + f64::from(i % 50),
        ..Settings::default()
    }
}

fn record(i: u32) -> Vec<u8> {
    settings(i).to_record().to_vec()
}

/// Saves `records` in order into `image`; the flash image afterwards.
fn saved(image: Vec<u8>, records: &[Vec<u8>]) -> Vec<u8> {
    let flash = Flash::from_image(BASE, image);
    let mut s = store(flash.clone());
    for r in records {
        block_on(s.save(r)).expect("save without a power cut");
    }
    flash.image()
}

fn erased() -> Vec<u8> {
    vec![0xFF; 2 * SECTOR]
}

/// What the firmware before this store left: the record written raw at the
/// start of sector 11, padded to whole words; sector 10 as given.
fn legacy_image(record: &[u8], sector10: u8) -> Vec<u8> {
    let mut image = erased();
    image[..SECTOR].fill(sector10);
    image[SECTOR..SECTOR + record.len()].copy_from_slice(record);
    image
}

/// Program/erase operations of a `save` of `new` on `image`, uncut.
fn save_ops(image: &[u8], new: &[u8]) -> u64 {
    let flash = Flash::from_image(BASE, image.to_vec());
    block_on(store(flash.clone()).save(new)).expect("uncut save");
    flash.ops()
}

/// Cuts a save of `new` on `image` at every step, in every way, with the
/// store `make` builds; after each cut the boot must load `old` or `new`
/// (`old` empty: nothing saved yet), a second boot the same, and the store
/// must take a further save. Returns the cut points tried and a line for
/// each that broke a rule.
fn cut_every_step<S: SettingsStore>(
    make: impl Fn(Flash) -> S,
    image: &[u8],
    old: &[u8],
    new: &[u8],
) -> (u64, Vec<String>) {
    let ops = {
        let flash = Flash::from_image(BASE, image.to_vec());
        block_on(make(flash.clone()).save(new)).expect("uncut save");
        flash.ops()
    };
    let load = |flash: Flash| {
        let mut record = vec![0u8; RECORD_LEN];
        let n = block_on(make(flash).load(&mut record));
        record.truncate(n);
        record
    };
    let later = record(999);
    let (mut tried, mut broken) = (0, Vec::new());
    for at_op in 0..ops {
        for tear in Tear::ALL {
            tried += 1;
            let at = format!("cut at op {at_op}/{ops} ({tear:?})");
            let flash = Flash::from_image(BASE, image.to_vec())
                .with_power_cut(Some(PowerCut { at_op, tear }));
            if block_on(make(flash.clone()).save(new)).is_ok() {
                broken.push(format!("{at}: the save did not report the lost power"));
            }
            let after_cut = flash.image();
            let loaded = load(Flash::from_image(BASE, after_cut.clone()));
            if loaded != old && loaded != new {
                broken.push(format!(
                    "{at}: boot loaded {} bytes, neither old nor new",
                    loaded.len()
                ));
                continue;
            }
            // The boot may repair the flash; a second boot agrees with it,
            // and the next save lands.
            let rebooted = Flash::from_image(BASE, after_cut);
            let mut s = make(rebooted.clone());
            let mut again = vec![0u8; RECORD_LEN];
            let n = block_on(s.load(&mut again));
            again.truncate(n);
            if again != loaded {
                broken.push(format!("{at}: a second boot loads something else"));
            }
            if let Err(e) = block_on(s.save(&later)) {
                broken.push(format!("{at}: the next save failed: {e}"));
            } else if load(Flash::from_image(BASE, rebooted.image())) != later {
                broken.push(format!("{at}: the next save does not load"));
            }
        }
    }
    // Past the last step the save is whole.
    let flash = Flash::from_image(BASE, image.to_vec()).with_power_cut(Some(PowerCut {
        at_op: ops,
        tear: Tear::FirstHalf,
    }));
    block_on(make(flash.clone()).save(new)).expect("the cut comes after the save");
    if load(Flash::from_image(BASE, flash.image())) != new {
        broken.push("uncut save does not load".into());
    }
    (tried, broken)
}

/// [`cut_every_step`] with the firmware's store; fails on any broken rule.
fn check_every_cut(image: &[u8], old: &[u8], new: &[u8]) -> u64 {
    let (tried, broken) = cut_every_step(store, image, old, new);
    assert!(
        broken.is_empty(),
        "{} of {tried} cut points: {broken:#?}",
        broken.len()
    );
    tried
}

/// The scheme the firmware had before: erase sector 11, write the record.
struct EraseAndRewrite(Flash);

impl SettingsStore for EraseAndRewrite {
    async fn load(&mut self, buf: &mut [u8]) -> usize {
        let at = BASE + SECTOR as u32;
        match self.0.read(at, buf).await {
            Ok(()) => buf.len(),
            Err(_) => 0,
        }
    }

    async fn save(&mut self, record: &[u8]) -> Result<(), &'static str> {
        let at = BASE + SECTOR as u32;
        self.0
            .erase(at, at + SECTOR as u32)
            .await
            .map_err(|_| "erase")?;
        let mut padded = record.to_vec();
        padded.resize(record.len().next_multiple_of(4), 0xFF);
        self.0.write(at, &padded).await.map_err(|_| "write")
    }

    // The earlier scheme had no presets.
    async fn load_preset(&mut self, _n: u8) -> Option<PointCm> {
        None
    }

    async fn save_preset(&mut self, _n: u8, _p: Option<PointCm>) -> Result<(), &'static str> {
        Err("no presets")
    }
}

#[test]
fn the_harness_catches_the_earlier_erase_and_rewrite_scheme() {
    // Its loads return the whole buffer, which the rule compares with the
    // record: boot from a record it wrote itself.
    let image = {
        let flash = Flash::erased(BASE, 2);
        block_on(EraseAndRewrite(flash.clone()).save(&record(1))).unwrap();
        flash.image()
    };
    let (tried, broken) = cut_every_step(EraseAndRewrite, &image, &record(1), &record(2));
    assert!(
        broken.len() as u64 > tried / 2,
        "a cut during erase or rewrite loses the settings: {} of {tried}",
        broken.len()
    );
}

#[test]
fn a_cut_at_any_step_of_a_save_boots_the_old_or_the_new_settings() {
    let mut cuts = 0;
    // The first save ever: nothing or the new record.
    cuts += check_every_cut(&erased(), &[], &record(1));
    // After 1..=7 saves: every position in a sector, and the saves that
    // hand over to the other sector (erase it, move the newest record).
    let history: Vec<Vec<u8>> = (1..=7).map(record).collect();
    for n in 1..=history.len() {
        let image = saved(erased(), &history[..n]);
        assert_eq!(boot(image.clone()), history[n - 1]);
        cuts += check_every_cut(&image, &history[n - 1], &record(100 + n as u32));
    }
    eprintln!("single saves: {cuts} cut points (step x tear)");
}

#[test]
fn a_record_of_the_earlier_layout_loads_and_migrates_without_a_window_of_loss() {
    let old = record(7);
    let mut raw = old.clone();
    raw.resize(old.len().next_multiple_of(4), 0xFF);
    // Sector 10 as shipped (erased) or holding anything.
    let mut cuts = 0;
    for sector10 in [0xFF, 0x00, 0x5A] {
        let image = legacy_image(&raw, sector10);
        assert_eq!(boot(image.clone()), old, "first boot loads the old record");
        cuts += check_every_cut(&image, &old, &record(8));
        // Migrated: later saves go through the map and the old record
        // never comes back.
        let image = saved(image, &[record(8), record(9), record(10), record(11)]);
        assert_eq!(boot(image), record(11));
    }
    eprintln!("migrations: {cuts} cut points (step x tear)");
    // A record the old firmware only half wrote was lost then already: the
    // store starts afresh and takes a save.
    let mut torn = erased();
    torn[SECTOR..SECTOR + 40].copy_from_slice(&raw[..40]);
    assert_eq!(boot(torn.clone()), Vec::<u8>::new());
    assert_eq!(boot(saved(torn, &[record(3)])), record(3));
}

#[test]
fn a_cut_at_any_step_of_a_sequence_of_saves_boots_the_last_or_the_interrupted_one() {
    let sequence: Vec<Vec<u8>> = (1..=10).map(record).collect();
    let total = {
        let flash = Flash::erased(BASE, 2);
        let mut s = store(flash.clone());
        for r in &sequence {
            block_on(s.save(r)).expect("uncut");
        }
        assert!(flash.stats().erases >= 3, "the sequence hands sectors over");
        flash.ops()
    };
    for at_op in 0..total {
        for tear in Tear::ALL {
            let flash = Flash::erased(BASE, 2).with_power_cut(Some(PowerCut { at_op, tear }));
            let mut s = store(flash.clone());
            let interrupted = sequence
                .iter()
                .position(|r| block_on(s.save(r)).is_err())
                .expect("the power goes during the sequence");
            let loaded = boot(flash.image());
            let last = interrupted
                .checked_sub(1)
                .map_or(&[][..], |i| &sequence[i][..]);
            assert!(
                loaded == last || loaded == sequence[interrupted],
                "cut at op {at_op}/{total} ({tear:?}) during save {interrupted}: neither"
            );
        }
    }
    eprintln!(
        "sequence of {} saves: {total} steps x {} tears",
        sequence.len(),
        Tear::ALL.len()
    );
}

#[test]
fn a_second_cut_while_the_boot_repairs_the_flash_still_boots_old_or_new() {
    let history: Vec<Vec<u8>> = (1..=4).map(record).collect();
    let new = record(50);
    let mut repairs = 0;
    // Just before a sector hand-over and inside one.
    for n in [2, 3, 4] {
        let image = saved(erased(), &history[..n]);
        let old = &history[n - 1];
        let ops = save_ops(&image, &new);
        for at_op in 0..ops {
            for tear in Tear::ALL {
                let flash = Flash::from_image(BASE, image.clone())
                    .with_power_cut(Some(PowerCut { at_op, tear }));
                let _ = block_on(store(flash.clone()).save(&new));
                let after_cut = flash.image();
                // How many operations the boot's repair takes, then cut
                // each of them.
                let probe = Flash::from_image(BASE, after_cut.clone());
                let mut buf = vec![0u8; RECORD_LEN];
                block_on(store(probe.clone()).load(&mut buf));
                repairs += u64::from(probe.ops() > 0);
                for second in 0..probe.ops() {
                    for tear2 in Tear::ALL {
                        let flash2 = Flash::from_image(BASE, after_cut.clone()).with_power_cut(
                            Some(PowerCut {
                                at_op: second,
                                tear: tear2,
                            }),
                        );
                        let mut buf = vec![0u8; RECORD_LEN];
                        block_on(store(flash2.clone()).load(&mut buf));
                        let loaded = boot(flash2.image());
                        assert!(
                            loaded == *old || loaded == new,
                            "cut at op {at_op} ({tear:?}), then at boot op {second} ({tear2:?})"
                        );
                    }
                }
            }
        }
    }
    assert!(repairs > 0, "some cuts leave the boot something to repair");
    eprintln!("boots that repair the flash: {repairs}");
}

/// One write to the store: a settings record, or preset n set (`Some`) or
/// cleared.
#[derive(Clone)]
enum Write {
    Record(Vec<u8>),
    Preset(u8, Option<PointCm>),
}

impl Write {
    fn apply<S: SettingsStore>(&self, s: &mut S) -> Result<(), &'static str> {
        match self {
            Write::Record(r) => block_on(s.save(r)),
            Write::Preset(n, p) => block_on(s.save_preset(*n, *p)),
        }
    }
}

/// Presets the preset tests use (the scaled sectors hold a record and a
/// few dozen presets).
const PRESETS_TRIED: u8 = 4;

/// A distinct board point number `i`, cm (exact in f32, as saved).
fn spot(i: u32) -> PointCm {
    PointCm::new(f64::from(i % 200) * 0.5 - 30.0, 17.25 - f64::from(i % 64))
}

/// What a boot reads: the record and presets 1..=[`PRESETS_TRIED`].
fn boot_all(image: Vec<u8>) -> (Vec<u8>, Vec<Option<PointCm>>) {
    let mut s = store(Flash::from_image(BASE, image));
    let mut record = vec![0u8; RECORD_LEN];
    let n = block_on(s.load(&mut record));
    record.truncate(n);
    let presets = (1..=PRESETS_TRIED)
        .map(|k| block_on(s.load_preset(k)))
        .collect();
    (record, presets)
}

/// `writes` in order on `image`, uncut; the image afterwards.
fn written(image: Vec<u8>, writes: &[Write]) -> Vec<u8> {
    let flash = Flash::from_image(BASE, image);
    let mut s = store(flash.clone());
    for w in writes {
        w.apply(&mut s).expect("write without a power cut");
    }
    flash.image()
}

/// Cuts `write` (of preset `n`, to `new`) on `image` at every step, in every
/// way: each boot loads the record and every other preset as they were,
/// and preset `n` old or new; a second boot agrees, and the next preset
/// write lands. Returns the cut points tried and whether the write erased
/// a sector (a hand-over).
fn check_every_preset_cut(image: &[u8], n: u8, new: Option<PointCm>) -> (u64, bool) {
    let before = boot_all(image.to_vec());
    let write = Write::Preset(n, new);
    let uncut = Flash::from_image(BASE, image.to_vec());
    write
        .apply(&mut store(uncut.clone()))
        .expect("uncut preset write");
    let (ops, erased) = (uncut.ops(), uncut.stats().erases > 0);
    let mut after_uncut = before.clone();
    after_uncut.1[usize::from(n - 1)] = new;
    assert_eq!(boot_all(uncut.image()), after_uncut, "uncut write loads");
    let mut tried = 0;
    for at_op in 0..ops {
        for tear in Tear::ALL {
            tried += 1;
            let at = format!("preset {n} cut at op {at_op}/{ops} ({tear:?})");
            let flash = Flash::from_image(BASE, image.to_vec())
                .with_power_cut(Some(PowerCut { at_op, tear }));
            assert!(
                write.apply(&mut store(flash.clone())).is_err(),
                "{at}: no error"
            );
            let cut = flash.image();
            let loaded = boot_all(cut.clone());
            assert!(
                loaded == before || loaded == after_uncut,
                "{at}: booted {loaded:?}"
            );
            // The boot may repair; a second boot agrees, the next write lands.
            let rebooted = Flash::from_image(BASE, cut);
            let mut s = store(rebooted.clone());
            let mut record = vec![0u8; RECORD_LEN];
            block_on(s.load(&mut record));
            assert_eq!(boot_all(rebooted.image()), loaded, "{at}: second boot");
            let next = spot(999);
            block_on(s.save_preset(n, Some(next))).unwrap_or_else(|e| panic!("{at}: {e}"));
            let (record, presets) = boot_all(rebooted.image());
            assert_eq!(record, loaded.0, "{at}: the record after the next write");
            assert_eq!(presets[usize::from(n - 1)], Some(next), "{at}: next write");
        }
    }
    (tried, erased)
}

#[test]
fn a_cut_at_any_step_of_a_preset_write_boots_the_old_or_the_new_preset() {
    // A store with records and presets interleaved, cut while presets are
    // set, changed and cleared at every fill level of a sector, through
    // the hand-overs to the other sector.
    let mut history = vec![Write::Record(record(1))];
    let (mut cuts, mut handovers) = (0, 0);
    for i in 0..120u32 {
        let n = 1 + (i % u32::from(PRESETS_TRIED)) as u8;
        let new = (i % 5 != 4).then(|| spot(i));
        let image = written(erased(), &history);
        let (tried, erased) = check_every_preset_cut(&image, n, new);
        cuts += tried;
        handovers += u64::from(erased);
        history.push(Write::Preset(n, new));
        if i % 40 == 39 {
            history.push(Write::Record(record(10 + i)));
        }
    }
    assert!(handovers > 0, "some preset writes hand the sector over");
    eprintln!("preset writes: {cuts} cut points (step x tear), {handovers} hand-overs");
}

#[test]
fn a_preset_write_on_a_record_of_the_earlier_layout_is_refused_until_a_save() {
    let old = record(7);
    let mut raw = old.clone();
    raw.resize(old.len().next_multiple_of(4), 0xFF);
    let image = legacy_image(&raw, 0xFF);
    let flash = Flash::from_image(BASE, image.clone());
    let refused = block_on(store(flash.clone()).save_preset(2, Some(spot(5))));
    assert!(refused.is_err(), "{refused:?}");
    assert_eq!(flash.image(), image, "nothing written");
    // After the migrating save, presets are written.
    let image = written(image, &[Write::Record(record(8))]);
    let (cuts, _) = check_every_preset_cut(&image, 2, Some(spot(5)));
    assert!(cuts > 0);
    let image = written(image, &[Write::Preset(2, Some(spot(5)))]);
    let (record_now, presets) = boot_all(written(image, &[Write::Record(record(9))]));
    assert_eq!(record_now, record(9));
    assert_eq!(presets[1], Some(spot(5)));
}

/// The image `image` leaves after a save of `new` cut at `cut` (`None`:
/// uncut), and whether the save reported success.
fn after_save(image: &[u8], new: &[u8], cut: Option<PowerCut>) -> (Vec<u8>, bool) {
    let flash = Flash::from_image(BASE, image.to_vec()).with_power_cut(cut);
    let ok = block_on(store(flash.clone()).save(new)).is_ok();
    (flash.image(), ok)
}

#[test]
fn a_cut_first_migration_then_saves_never_boot_defaults_once_a_save_succeeded() {
    // A board with a record in the earlier layout; its first (migrating)
    // save is cut anywhere (or not), a later save lands, and then every
    // step of the next save and of a preset write is cut: the boot loads
    // the last saved or the new record, never nothing.
    let old = record(7);
    let mut raw = old.clone();
    raw.resize(old.len().next_multiple_of(4), 0xFF);
    let legacy = legacy_image(&raw, 0xFF);
    let ops = save_ops(&legacy, &record(8));
    let mut cuts = 0;
    let firsts = (0..ops)
        .flat_map(|at_op| Tear::ALL.map(|tear| Some(PowerCut { at_op, tear })))
        .chain([None]);
    for first in firsts {
        let (cut, ok) = after_save(&legacy, &record(8), first);
        let loaded = boot(cut.clone());
        assert!(loaded == old || loaded == record(8), "{first:?}: neither");
        assert!(ok || first.is_some());
        // Every step of the save after it (from what the cut left).
        cuts += check_every_cut(&cut, &loaded, &record(9));
        let (image, ok) = after_save(&cut, &record(9), None);
        assert!(ok, "{first:?}: the save after the cut");
        assert_eq!(boot(image.clone()), record(9), "{first:?}");
        let (tried, broken) = cut_every_step(store, &image, &record(9), &record(10));
        assert!(
            broken.is_empty(),
            "first save cut at {first:?}; {} of {tried} cut points of the third: {broken:#?}",
            broken.len()
        );
        cuts += tried;
        let (tried, _) = check_every_preset_cut(&image, 3, Some(spot(3)));
        cuts += tried;
    }
    eprintln!("cut migrations then saves: {cuts} cut points (step x tear)");
}
