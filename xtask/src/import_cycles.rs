//! Import cycles between the files of a module tree (non-test code): a
//! file's module imports another's when it names it by path (`use`, or
//! an inline `crate::…` / `super::…` path); `mod` declarations are not
//! imports. The sequencer's files must form no cycle (ARCHITECTURE.md,
//! "The sequencer inside"), and laser-app's top-level modules must import
//! only modules of their own layer or below (ARCHITECTURE.md, "Layers of
//! laser-app"); the tests below check both.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module, as its path below the tree's root (`[]`: the root).
type Module = Vec<String>;

/// The modules of the tree at `dir` (module path `crate_path`, e.g.
/// `crate::sequencer`) and the modules each imports.
pub fn import_graph(
    dir: &Path,
    crate_path: &str,
) -> std::io::Result<BTreeMap<Module, BTreeSet<Module>>> {
    let mut sources = BTreeMap::new();
    collect(dir, dir, &mut sources)?;
    let modules: BTreeSet<Module> = sources.keys().cloned().collect();
    let mut graph = BTreeMap::new();
    for (module, text) in &sources {
        let mut imports = BTreeSet::new();
        for path in paths(text) {
            let Some(absolute) = resolve(module, &path, crate_path) else {
                continue;
            };
            // The longest prefix that is a module of the tree.
            let target = (0..=absolute.len())
                .rev()
                .map(|k| absolute[..k].to_vec())
                .find(|m| modules.contains(m));
            if let Some(target) = target.filter(|t| t != module) {
                imports.insert(target);
            }
        }
        graph.insert(module.clone(), imports);
    }
    Ok(graph)
}

/// The import cycles of `graph`: its strongly connected components of
/// more than one module, each sorted.
pub fn cycles(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    let names: Vec<&Module> = graph.keys().collect();
    let index_of = |m: &Module| names.iter().position(|n| *n == m);
    let edges: Vec<Vec<usize>> = names
        .iter()
        .map(|m| graph[*m].iter().filter_map(index_of).collect())
        .collect();
    let mut tarjan = Tarjan {
        edges: &edges,
        index: vec![None; names.len()],
        low: vec![0; names.len()],
        stack: Vec::new(),
        on_stack: vec![false; names.len()],
        next: 0,
        components: Vec::new(),
    };
    for v in 0..names.len() {
        if tarjan.index[v].is_none() {
            tarjan.visit(v);
        }
    }
    tarjan
        .components
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut c: Vec<Module> = c.into_iter().map(|i| names[i].clone()).collect();
            c.sort();
            c
        })
        .collect()
}

/// Tarjan's strongly connected components.
struct Tarjan<'a> {
    edges: &'a [Vec<usize>],
    index: Vec<Option<usize>>,
    low: Vec<usize>,
    stack: Vec<usize>,
    on_stack: Vec<bool>,
    next: usize,
    components: Vec<Vec<usize>>,
}

impl Tarjan<'_> {
    fn visit(&mut self, v: usize) {
        self.index[v] = Some(self.next);
        self.low[v] = self.next;
        self.next += 1;
        self.stack.push(v);
        self.on_stack[v] = true;
        for &w in &self.edges[v] {
            match self.index[w] {
                None => {
                    self.visit(w);
                    self.low[v] = self.low[v].min(self.low[w]);
                }
                Some(iw) if self.on_stack[w] => self.low[v] = self.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(self.low[v]) == self.index[v] {
            let mut component = Vec::new();
            while let Some(w) = self.stack.pop() {
                self.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            self.components.push(component);
        }
    }
}

/// Reads the non-test sources below `dir` (`tests.rs`, `proptests.rs`
/// and `#[cfg(test)]` items left out), keyed by module.
fn collect(root: &Path, dir: &Path, out: &mut BTreeMap<Module, String>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            collect(root, &path, out)?;
            continue;
        }
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if !name.ends_with(".rs") || name == "tests.rs" || name == "proptests.rs" {
            continue;
        }
        let relative = path.strip_prefix(root).unwrap_or(&path).with_extension("");
        let mut module: Module = relative
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if module.last().is_some_and(|l| l == "mod") {
            module.pop();
        }
        out.insert(module, without_tests(&std::fs::read_to_string(&path)?));
    }
    Ok(())
}

/// `text` without comments and without `#[cfg(test)]` items.
fn without_tests(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim_start().starts_with("#[cfg(test)]") {
            // Skip the item: `mod x;` or a braced block.
            let mut depth = 0i32;
            let mut opened = false;
            for item in lines.by_ref() {
                depth += item.matches('{').count() as i32 - item.matches('}').count() as i32;
                opened |= item.contains('{');
                if (!opened && item.trim_end().ends_with(';')) || (opened && depth <= 0) {
                    break;
                }
            }
            continue;
        }
        out.push_str(line.split("//").next().unwrap_or(""));
        out.push('\n');
    }
    out
}

/// Every path in `text` that starts with `crate::`, `super::` or
/// `self::`, with `use` groups (`a::{b, c::d}`) expanded one level.
fn paths(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    let is_ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut i = 0;
    while i < bytes.len() {
        let starts = ["crate::", "super::", "self::"]
            .iter()
            .any(|p| bytes[i..].starts_with(p.as_bytes()))
            && (i == 0 || !is_ident(bytes[i - 1]));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < bytes.len() && (is_ident(bytes[j]) || bytes[j] == b':') {
            j += 1;
        }
        let head = text[i..j].trim_end_matches(':').to_string();
        if text[j..].starts_with('{') {
            let end = text[j..].find('}').map_or(text.len(), |e| j + e);
            for item in text[j + 1..end].split(',') {
                let item = item.trim().trim_start_matches('{');
                if !item.is_empty() {
                    out.push(format!("{head}::{item}"));
                }
            }
            i = end;
        } else {
            out.push(head);
            i = j;
        }
    }
    out
}

/// The module path below the tree's root that `path`, written in
/// `module`, names (`None`: outside the tree).
fn resolve(module: &Module, path: &str, crate_path: &str) -> Option<Module> {
    let mut parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
    let mut base: Module;
    if let Some(rest) = path.strip_prefix(&format!("{crate_path}::")) {
        base = Vec::new();
        parts = rest.split("::").filter(|p| !p.is_empty()).collect();
    } else if parts.first() == Some(&"self") {
        base = module.clone();
        parts.remove(0);
    } else if parts.first() == Some(&"super") {
        base = module.clone();
        while parts.first() == Some(&"super") {
            base.pop()?;
            parts.remove(0);
        }
    } else {
        return None;
    }
    base.extend(parts.iter().map(|p| p.trim().to_string()));
    Some(base)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(files: &[(&str, &str)]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "xtask-import-cycles-{}-{}",
            std::process::id(),
            files.len()
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
                "#[cfg(test)]\nmod tests {\n    use super::super::a::X;\n}\n",
            ),
            ("tests.rs", "use super::a;\n"),
        ]);
        let graph = import_graph(&dir, "crate::seq").unwrap();
        let module = |m: &str| vec![m.to_string()];
        assert_eq!(
            graph[&module("a")],
            BTreeSet::from([module("b"), module("c")])
        );
        assert!(graph[&module("c")].is_empty(), "test items are not imports");
        assert_eq!(cycles(&graph), vec![vec![module("a"), module("b")]]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_sequencer_has_no_import_cycle() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware/app/src/sequencer");
        let graph = import_graph(&dir, "crate::sequencer").unwrap();
        assert!(graph.len() > 20, "the sequencer's files were read");
        let found = cycles(&graph);
        assert!(
            found.is_empty(),
            "import cycles in the sequencer: {found:?}"
        );
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
}
