use super::*;

fn tree(files: &[(&str, &str)]) -> std::path::PathBuf {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "xtask-import-cycles-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    dir
}

#[test]
fn a_child_named_without_self_is_an_import() {
    // `mod x; use x::Y;` imports x as `self::x::Y` would; `other::x::Y`
    // (x not at the start of the path) and a child of another module do
    // not.
    let dir = tree(&[
        ("mod.rs", "mod outer;\nmod solo;\nuse outer::Shared;\n"),
        (
            "outer/mod.rs",
            "mod inner;\npub use inner::Item;\npub struct Shared;\n",
        ),
        ("outer/inner.rs", "use super::Shared;\npub struct Item;\n"),
        (
            "solo.rs",
            "use heapless::inner::Vec;\nfn f() { other::outer::g() }\n",
        ),
    ]);
    let graph = import_graph(&dir, "crate::seq").unwrap();
    let module = |m: &[&str]| m.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(graph[&module(&[])], BTreeSet::from([module(&["outer"])]));
    assert_eq!(
        graph[&module(&["outer"])],
        BTreeSet::from([module(&["outer", "inner"])])
    );
    assert!(graph[&module(&["solo"])].is_empty(), "{graph:?}");
    assert_eq!(
        cycles(&graph),
        vec![vec![module(&["outer"]), module(&["outer", "inner"])]]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_cycle_through_use_groups_and_super_paths_is_found() {
    let dir = tree(&[
        ("mod.rs", "mod a;\nmod b;\n"),
        ("a.rs", "use crate::seq::{b::Thing, c};\n"),
        (
            "b.rs",
            "// use super::c::X; (a comment)\nfn f() { super::a::g() }\n",
        ),
        (
            "c.rs",
            "#[cfg(test)]\nmod tests {\n    use super::super::a::X;\n}\n\
             pub(in crate::seq) fn h() {}\n",
        ),
        ("tests.rs", "use super::a;\n"),
    ]);
    let graph = import_graph(&dir, "crate::seq").unwrap();
    let module = |m: &str| vec![m.to_string()];
    assert_eq!(
        graph[&module("a")],
        BTreeSet::from([module("b"), module("c")])
    );
    assert!(
        graph[&module("c")].is_empty(),
        "test items and visibilities are not imports"
    );
    assert_eq!(cycles(&graph), vec![vec![module("a"), module("b")]]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// laser-app's layers, bottom to top (ARCHITECTURE.md): a module may
/// import modules of its own row or of rows before it. `log` and
/// `build_info` are utilities every layer may use.
const LAYERS: &[&[&str]] = &[
    &["log", "build_info"],
    &["text"],
    &["domain"],
    &["settings"],
    &["status", "laser_gate"],
    &["laser_controls"],
    &["grbl"],
    &["command", "outbound"],
    &["servo", "galvo", "stepper"],
    &["sequencer"],
    &["pelco"],
    &["usb", "cli"],
    &["app"],
];

/// The row of top-level module `name`.
fn layer_of(name: &str) -> Option<usize> {
    LAYERS.iter().position(|row| row.contains(&name))
}

/// Imports between laser-app's top-level modules that go up a layer
/// (`(from, to)`), given the file graph of `firmware/app/src`.
fn upward_imports(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<(String, String)> {
    let mut upward = BTreeSet::new();
    for (from, targets) in graph {
        // The crate root declares the modules; it is no layer.
        let Some(from_top) = from.first().filter(|m| *m != "lib") else {
            continue;
        };
        for to in targets {
            let Some(to_top) = to.first() else { continue };
            if to_top == from_top {
                continue;
            }
            match (layer_of(from_top), layer_of(to_top)) {
                (Some(a), Some(b)) if b <= a => {}
                _ => {
                    upward.insert((from_top.clone(), to_top.clone()));
                }
            }
        }
    }
    upward.into_iter().collect()
}

#[test]
fn an_upward_import_is_found() {
    let module = |m: &str| vec![m.to_string()];
    let graph = BTreeMap::from([
        (module("text"), BTreeSet::from([module("sequencer")])),
        (module("sequencer"), BTreeSet::from([module("text")])),
        (module("mystery"), BTreeSet::new()),
        (module("app"), BTreeSet::from([module("mystery")])),
    ]);
    assert_eq!(
        upward_imports(&graph),
        vec![
            ("app".to_owned(), "mystery".to_owned()),
            ("text".to_owned(), "sequencer".to_owned())
        ]
    );
}

#[test]
fn laser_app_imports_only_its_own_layer_or_below() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/app/src");
    let graph = import_graph(&dir, "crate").unwrap();
    let tops: BTreeSet<&String> = graph
        .keys()
        .filter_map(|m| m.first())
        .filter(|m| *m != "lib")
        .collect();
    for top in &tops {
        assert!(
            layer_of(top).is_some(),
            "laser-app module {top} is in no layer of ARCHITECTURE.md (add it to LAYERS)"
        );
    }
    let upward = upward_imports(&graph);
    assert!(
        upward.is_empty(),
        "upward imports between laser-app's layers: {upward:?}"
    );
    // Between the top-level modules (one row may hold several).
    let mut tops_graph: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (from, targets) in &graph {
        let Some(from_top) = from.first().filter(|m| *m != "lib") else {
            continue;
        };
        let entry = tops_graph.entry(vec![from_top.clone()]).or_default();
        for to in targets.iter().filter_map(|t| t.first()) {
            if to != from_top {
                entry.insert(vec![to.clone()]);
            }
        }
    }
    let found = cycles(&tops_graph);
    assert!(
        found.is_empty(),
        "import cycles between laser-app's layers: {found:?}"
    );
}

/// The sequencer's core: `Core` (machine.rs) and the files that extend it.
const CORE_MODULES: &[&str] = &[
    "machine",
    "commands",
    "controls",
    "presets",
    "report",
    "servo_setup",
    "run/points",
    "faults/servo",
];

#[test]
fn the_gcode_session_and_the_drivers_stay_below_the_core() {
    // ARCHITECTURE.md, "The sequencer inside": the session and the drivers
    // work on what they are handed (a Session, a Stage), never on `Core`.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/app/src/sequencer");
    let graph = import_graph(&dir, "crate::sequencer").unwrap();
    let mut texts = BTreeMap::new();
    collect(&dir, &dir, &mut texts).unwrap();
    let below = |m: &Module| {
        let in_layer = m
            .first()
            .is_some_and(|top| top == "gcode" || top == "drivers");
        in_layer && !m.last().is_some_and(|last| last.ends_with("_tests"))
    };
    let core: BTreeSet<Module> = CORE_MODULES
        .iter()
        .map(|m| m.split('/').map(str::to_owned).collect())
        .collect();
    let mut offenders = Vec::new();
    for (module, targets) in graph.iter().filter(|(m, _)| below(m)) {
        for target in targets.intersection(&core) {
            offenders.push(format!("{} imports {}", module.join("/"), target.join("/")));
        }
        if texts.get(module).is_some_and(|t| t.contains("impl Core")) {
            offenders.push(format!("{} extends Core", module.join("/")));
        }
    }
    assert!(graph.keys().filter(|m| below(m)).count() > 20, "{graph:?}");
    assert!(offenders.is_empty(), "{offenders:#?}");
}

/// Whether `line` converts between cm and mm by hand: a factor of 10 (or
/// 0.1) on a line that names a length in cm or mm.
fn converts_cm_mm_by_hand(line: &str) -> bool {
    let names_length = ["_cm", "_mm", "cm(", "mm("]
        .iter()
        .any(|u| line.contains(u));
    let factor = ["* 10.0", "10.0 *", "/ 10.0", "* 0.1", "0.1 *"]
        .iter()
        .any(|f| {
            line.match_indices(f).any(|(i, _)| {
                // `110.0 *` or `* 10.05` are other numbers.
                let before = line[..i].chars().next_back();
                let after = line[i + f.len()..].chars().next();
                !before.is_some_and(|c| c.is_ascii_digit() || c == '.')
                    && !after.is_some_and(|c| c.is_ascii_digit())
            })
        });
    names_length && factor
}

#[test]
fn only_domain_units_converts_cm_and_mm() {
    assert!(converts_cm_mm_by_hand("let d_mm = 10.0 * d_cm;"));
    assert!(converts_cm_mm_by_hand("PointCm::new(p.x_mm / 10.0, 0.0)"));
    assert!(!converts_cm_mm_by_hand(
        "let deg = f64::from(tenths) / 10.0;"
    ));
    assert!(!converts_cm_mm_by_hand("let x_mm = 110.0 * k;"));
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/app/src");
    let mut texts = BTreeMap::new();
    collect(&dir, &dir, &mut texts).unwrap();
    let units: Module = vec!["domain".into(), "units".into()];
    let offenders: Vec<String> = texts
        .iter()
        .filter(|(m, _)| **m != units && !m.last().is_some_and(|l| l.ends_with("_tests")))
        .flat_map(|(m, text)| {
            text.lines()
                .filter(|l| converts_cm_mm_by_hand(l))
                .map(move |l| format!("{}: {}", m.join("/"), l.trim()))
        })
        .collect();
    assert!(
        offenders.is_empty(),
        "cm <-> mm by hand (use domain::units): {offenders:#?}"
    );
}

/// The source trees of the workspace's crates (the separate workspaces
/// `firmware/qemu-m4` and `firmware/bench-m4` included), as
/// `(crate, directory below the repository root)`.
const CRATES: &[(&str, &str)] = &[
    ("laser-app", "firmware/app/src"),
    ("kinematics-core", "kinematics-core/src"),
    ("galvo-planner", "galvo-planner/src"),
    ("fashionstar", "firmware/fashionstar/src"),
    ("pelco", "firmware/pelco/src"),
    ("laser-sim", "firmware/sim/src"),
    ("galvo-dma", "firmware/galvo-dma/src"),
    ("qemu-m4", "firmware/qemu-m4/src"),
    ("firmware", "firmware/src"),
    ("xtask", "xtask/src"),
    ("camera-calib", "xtask/camera/src"),
    ("bench-m4", "firmware/bench-m4/src"),
];

/// The import cycles that are still there (a ratchet: a new cycle fails
/// the check, and so does an entry whose cycle is gone, so the list only
/// shrinks): `(crate, its modules as paths below src, sorted, why it stays)`.
const KNOWN_CYCLES: &[(&str, &[&str], &str)] = &[];

/// A module as written in [`KNOWN_CYCLES`] (`a/b`).
fn module_name(module: &Module) -> String {
    module.join("/")
}

/// Every import cycle in the workspace's non-test code, as
/// `(crate, modules)`.
fn workspace_cycles() -> Vec<Named> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut found = Vec::new();
    for (name, dir) in CRATES {
        let graph = import_graph(&root.join(dir), "crate")
            .unwrap_or_else(|e| panic!("reading {dir} ({name}): {e}"));
        assert!(graph.len() > 1, "{dir} ({name}): its files were read");
        for cycle in cycles(&graph) {
            found.push((name.to_string(), cycle.iter().map(module_name).collect()));
        }
    }
    found
}

/// A cycle as `(crate, modules)`.
type Named = (String, Vec<String>);

/// The cycles of `found` not in `known` and the entries of `known` not
/// found (each entry's modules in any order).
fn unlisted_and_gone(found: &[Named], known: &[(&str, &[&str], &str)]) -> (Vec<Named>, Vec<Named>) {
    let known: Vec<Named> = known
        .iter()
        .map(|(name, modules, _)| {
            let mut modules: Vec<String> = modules.iter().map(|m| m.to_string()).collect();
            modules.sort();
            (name.to_string(), modules)
        })
        .collect();
    let unlisted = found
        .iter()
        .filter(|c| !known.contains(c))
        .cloned()
        .collect();
    let gone = known
        .iter()
        .filter(|c| !found.contains(c))
        .cloned()
        .collect();
    (unlisted, gone)
}

#[test]
fn a_new_cycle_and_a_listed_one_gone_are_both_found() {
    let cycle = |name: &str, modules: &[&str]| -> Named {
        (
            name.to_string(),
            modules.iter().map(|m| m.to_string()).collect(),
        )
    };
    let found = [cycle("a", &["x", "y"]), cycle("b", &["p", "q/r"])];
    let known: &[(&str, &[&str], &str)] = &[
        ("b", &["q/r", "p"], "left for: later"),
        ("c", &["u", "v"], "left for: later"),
    ];
    let (unlisted, gone) = unlisted_and_gone(&found, known);
    assert_eq!(unlisted, vec![cycle("a", &["x", "y"])]);
    assert_eq!(gone, vec![cycle("c", &["u", "v"])]);
}

#[test]
fn the_workspace_has_no_import_cycle_but_the_known_ones() {
    let (unlisted, gone) = unlisted_and_gone(&workspace_cycles(), KNOWN_CYCLES);
    assert!(
        unlisted.is_empty(),
        "import cycles not in KNOWN_CYCLES (break them: the items both \
         files need go to a file of their own that imports neither): {unlisted:?}"
    );
    assert!(
        gone.is_empty(),
        "KNOWN_CYCLES lists cycles that are no longer there (remove them; \
         a cycle that changed shape is listed with its modules now): {gone:?}"
    );
}

#[test]
fn known_cycles_say_why_they_stay() {
    for (name, modules, reason) in KNOWN_CYCLES {
        assert!(
            reason.starts_with("left for: ") && reason.len() > "left for: ".len(),
            "{name} {modules:?}: the reason must say \"left for: ...\""
        );
        assert!(
            modules.len() > 1,
            "{name} {modules:?}: a cycle has 2+ modules"
        );
        assert!(
            CRATES.iter().any(|(crate_name, _)| crate_name == name),
            "{name}: no such crate in CRATES"
        );
    }
}
