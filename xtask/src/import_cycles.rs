//! Import cycles between the files of a module tree (non-test code): a
//! file's module imports another's when it names it by path (`use`, or
//! an inline `crate::…` / `super::…` / `self::…` path); `mod` declarations
//! are not imports, but naming a child module without `self::`
//! (`mod x; use x::Y;`) is. The tests (`import_cycles/tests.rs`) check that no crate of
//! the workspace (the separate `qemu-m4` and `bench-m4` workspaces
//! included) has an import cycle but those its `KNOWN_CYCLES` lists (a
//! ratchet: a listed cycle that is gone fails too), that the sequencer's
//! files form no cycle (ARCHITECTURE.md, "The sequencer inside"), and that
//! laser-app's top-level modules import only modules of their own layer
//! or below (ARCHITECTURE.md, "Layers of laser-app").

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
        let children: BTreeSet<&str> = modules
            .iter()
            .filter(|m| m.len() == module.len() + 1 && m.starts_with(module))
            .filter_map(|m| m.last().map(String::as_str))
            .collect();
        for path in paths(text, &children) {
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
/// `self::` (not a `pub(in …)` visibility), or with one of the module's
/// `children` (returned as `self::child::…`), with `use` groups
/// (`a::{b, c::d}`) expanded one level.
fn paths(text: &str, children: &BTreeSet<&str>) -> Vec<String> {
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    let is_ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut i = 0;
    while i < bytes.len() {
        // A visibility (`pub(in crate::a)`) names a module but imports
        // nothing.
        let visibility = bytes[..i].trim_ascii_end().ends_with(b"(in");
        let at_word = i == 0 || !(is_ident(bytes[i - 1]) || bytes[i - 1] == b':');
        let child = at_word
            && children.iter().any(|c| {
                bytes[i..].starts_with(c.as_bytes()) && bytes[i + c.len()..].starts_with(b"::")
            });
        let starts = ["crate::", "super::", "self::"]
            .iter()
            .any(|p| bytes[i..].starts_with(p.as_bytes()))
            && (i == 0 || !is_ident(bytes[i - 1]))
            && !visibility;
        if !(starts || child) {
            i += 1;
            continue;
        }
        let prefix = if starts { "" } else { "self::" };
        let mut j = i;
        while j < bytes.len() && (is_ident(bytes[j]) || bytes[j] == b':') {
            j += 1;
        }
        let head = format!("{prefix}{}", text[i..j].trim_end_matches(':'));
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
mod tests;
