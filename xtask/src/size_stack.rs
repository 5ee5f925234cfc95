//! Stack frames of the firmware image, for `cargo xtask size`: every
//! function's entry `sub sp` (read from `llvm-objdump -d` of the release
//! ELF), checked against [`FRAME_BUDGET_BYTES`]. An interrupt-executor
//! task nests on top of whatever thread-mode stack it interrupts, so one
//! big frame can overflow the stack below the statics (flip-link): the
//! check keeps every frame small.

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, bail};

/// Largest stack frame (bytes reserved by one function's entry `sub sp`)
/// the image may hold.
pub const FRAME_BUDGET_BYTES: u64 = 8 * 1024;

/// Known frames over [`FRAME_BUDGET_BYTES`], each with the ceiling it
/// may not grow past (name part, bytes): the galvo loop's one-shot start
/// (the loop still built on the stack, then moved into its static), its
/// per-half prep (a prepared step built, then moved into its ring slot),
/// and the largest task poll (the sequencer's, thread mode; every task's
/// poll shares this name). To be brought under the budget and removed.
pub const FRAME_ALLOWANCES: [(&str, u64); 3] = [
    // In `scan/build.rs`: demangled as `<impl …::GalvoLoop>::start_in`.
    ("GalvoLoop>::start_in", 24 * 1024),
    ("GalvoLoop>::prep_up_to", 11_776),
    ("embassy_executor::raw::TaskStorage<F>::poll", 14 * 1024),
];

/// The frame `function` may have: its allowance or the budget.
fn limit_of(function: &str, budget: u64, allowances: &[(&str, u64)]) -> u64 {
    allowances
        .iter()
        .find(|(part, _)| function.contains(part))
        .map_or(budget, |&(_, ceiling)| ceiling.max(budget))
}

/// Instructions from a function's entry searched for its `sub sp`.
const PROLOGUE_INSTRUCTIONS: usize = 16;

/// One function's stack frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frame {
    /// Demangled function name.
    pub function: String,
    /// Bytes reserved by its entry `sub sp` instructions (pushes excluded).
    pub bytes: u64,
}

fn parse_imm(text: &str) -> Option<u64> {
    let text = text.trim().trim_start_matches('#');
    match text.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => text.parse().ok(),
    }
}

/// Bytes one instruction (mnemonic, operands) subtracts from `sp`, given
/// the values `movw`/`movt` put in registers so far in the prologue.
fn sub_sp_bytes(mnemonic: &str, operands: &[&str], regs: &HashMap<String, u64>) -> Option<u64> {
    if !matches!(mnemonic, "sub" | "sub.w" | "subw" | "subs") || operands.first() != Some(&"sp") {
        return None;
    }
    // `sub sp, #n` or `sub sp, sp, #n` / `sub sp, rN`.
    let last = operands.last()?;
    if operands.len() == 3 && operands[1] != "sp" {
        return None;
    }
    if last.starts_with('#') {
        parse_imm(last)
    } else {
        regs.get(*last).copied()
    }
}

/// Every function's entry frame in `disassembly` (output of
/// `llvm-objdump -d -C --no-show-raw-insn`), largest first; functions
/// without a `sub sp` are left out.
pub fn frames_of(disassembly: &str) -> Vec<Frame> {
    let mut frames = Vec::new();
    let mut current: Option<(String, u64, usize, HashMap<String, u64>)> = None;
    let mut finish = |current: &mut Option<(String, u64, usize, HashMap<String, u64>)>| {
        if let Some((function, bytes, _, _)) = current.take()
            && bytes > 0
        {
            frames.push(Frame { function, bytes });
        }
    };
    for line in disassembly.lines() {
        let trimmed = line.trim_end();
        if let Some(name) = function_header(trimmed) {
            finish(&mut current);
            current = Some((readable(name), 0, 0, HashMap::new()));
            continue;
        }
        let Some((_, bytes, seen, regs)) = current.as_mut() else {
            continue;
        };
        let Some((mnemonic, operands)) = instruction(trimmed) else {
            continue;
        };
        *seen += 1;
        if *seen > PROLOGUE_INSTRUCTIONS {
            continue;
        }
        let operands: Vec<&str> = operands.split(',').map(str::trim).collect();
        match (mnemonic, operands.as_slice()) {
            ("movw" | "mov.w", [reg, imm]) if imm.starts_with('#') => {
                if let Some(v) = parse_imm(imm) {
                    regs.insert((*reg).to_owned(), v);
                }
            }
            ("movt", [reg, imm]) => {
                if let Some(v) = parse_imm(imm) {
                    let low = regs.get(*reg).copied().unwrap_or(0) & 0xffff;
                    regs.insert((*reg).to_owned(), (v << 16) | low);
                }
            }
            _ => {
                if let Some(n) = sub_sp_bytes(mnemonic, &operands, regs) {
                    *bytes += n;
                }
            }
        }
    }
    finish(&mut current);
    frames.sort_by(|a, b| b.bytes.cmp(&a.bytes).then(a.function.cmp(&b.function)));
    frames
}

/// `name` with the legacy Rust mangling escapes (`$LT$`, `..`, …) that
/// `llvm-objdump -C` leaves replaced, and its hash suffix kept.
fn readable(name: &str) -> String {
    [
        ("$LT$", "<"),
        ("$GT$", ">"),
        ("$C$", ","),
        ("$u20$", " "),
        ("$RF$", "&"),
        ("$u5b$", "["),
        ("$u5d$", "]"),
        ("$u7b$", "{"),
        ("$u7d$", "}"),
        ("_<", "<"),
        ("..", "::"),
    ]
    .iter()
    .fold(name.to_owned(), |n, (from, to)| n.replace(from, to))
}

/// `08000ba8 <name>:` → `name`.
fn function_header(line: &str) -> Option<&str> {
    let (addr, rest) = line.split_once(' ')?;
    if addr.is_empty() || !addr.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    rest.strip_prefix('<')?.strip_suffix(">:")
}

/// ` 8000bb0:  \tsub\tsp, #0x8` → (`sub`, `sp, #0x8`).
fn instruction(line: &str) -> Option<(&str, &str)> {
    let (addr, rest) = line.split_once(':')?;
    let addr = addr.trim();
    if addr.is_empty() || !addr.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    let mut fields = rest.split('\t').map(str::trim).filter(|f| !f.is_empty());
    let mnemonic = fields.next()?;
    Some((mnemonic, fields.next().unwrap_or("")))
}

/// Fails, naming them, when frames exceed `budget` bytes (or their
/// ceiling in `allowances`).
pub fn check_frames(frames: &[Frame], budget: u64, allowances: &[(&str, u64)]) -> Result<()> {
    let over: Vec<String> = frames
        .iter()
        .filter_map(|f| {
            let limit = limit_of(&f.function, budget, allowances);
            (f.bytes > limit).then(|| format!("{} B (limit {} B) {}", f.bytes, limit, f.function))
        })
        .collect();
    if !over.is_empty() {
        bail!(
            "{} stack frame(s) exceed the {} B budget or their allowance:\n  {}",
            over.len(),
            budget,
            over.join("\n  ")
        );
    }
    Ok(())
}

/// Disassembles `elf` with the `llvm-objdump` next to `llvm_size`, prints
/// the five largest frames and checks them against [`FRAME_BUDGET_BYTES`].
pub fn report(elf: &Path, llvm_size: &Path) -> Result<()> {
    let objdump = llvm_size.with_file_name("llvm-objdump");
    let out = Command::new(&objdump)
        .args(["-d", "-C", "--no-show-raw-insn"])
        .arg(elf)
        .output()
        .with_context(|| format!("could not run {}", objdump.display()))?;
    if !out.status.success() {
        bail!(
            "llvm-objdump failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let frames = frames_of(&String::from_utf8_lossy(&out.stdout));
    if frames.is_empty() {
        bail!("no `sub sp` found in the disassembly of {}", elf.display());
    }
    println!("  largest stack frames (budget {FRAME_BUDGET_BYTES} B each):");
    for frame in frames.iter().take(5) {
        println!("  {:>7} B  {}", frame.bytes, frame.function);
    }
    check_frames(&frames, FRAME_BUDGET_BYTES, &FRAME_ALLOWANCES)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SNIPPET: &str = "
firmware:\tfile format elf32-littlearm

Disassembly of section .text:

08000ba8 <core::fmt::write>:
 8000ba8:      \tpush\t{r4, r5, r6, r7, lr}
 8000baa:      \tadd\tr7, sp, #0xc
 8000bac:      \tstr\tr8, [sp, #-4]!
 8000bb0:      \tsub\tsp, #0x8
 8000bb2:      \tbl\t0x8000c90 <x>

0800441c <embassy_executor::raw::TaskStorage$LT$F$GT$::poll>:
 800441a:      \tpush\t{r4, r5, r6, r7, lr}
 800441c:      \tsub.w\tsp, sp, #0x11600
 8004420:      \tsub\tsp, #0x4
 8004422:      \tmovs\tr0, #0x0

080036c0 <laser_app::galvo::scan::GalvoLoop::apply_pending_config>:
 80036c0:      \tpush\t{r4, r5, r6, r7, lr}
 80036c2:      \tsubw\tsp, sp, #0x87c
 80036c6:      \tbx\tlr

08005000 <big_by_register>:
 8005000:      \tpush\t{r7, lr}
 8005002:      \tmovw\tr12, #0x2345
 8005006:      \tmovt\tr12, #0x1
 800500a:      \tsub\tsp, r12
 800500c:      \tbx\tlr

08006000 <leaf>:
 8006000:      \tbx\tlr

08007000 <late_sub_ignored>:
 8007000:      \tnop
 8007002:      \tnop
 8007004:      \tnop
 8007006:      \tnop
 8007008:      \tnop
 800700a:      \tnop
 800700c:      \tnop
 800700e:      \tnop
 8007010:      \tnop
 8007012:      \tnop
 8007014:      \tnop
 8007016:      \tnop
 8007018:      \tnop
 800701a:      \tnop
 800701c:      \tnop
 800701e:      \tnop
 8007020:      \tsub\tsp, #0x100
";

    #[test]
    fn reads_entry_frames_from_objdump_text() {
        let frames = frames_of(SNIPPET);
        let got: Vec<(&str, u64)> = frames
            .iter()
            .map(|f| (f.function.as_str(), f.bytes))
            .collect();
        assert_eq!(
            got,
            vec![
                ("big_by_register", 0x1_2345),
                ("embassy_executor::raw::TaskStorage<F>::poll", 0x11604),
                (
                    "laser_app::galvo::scan::GalvoLoop::apply_pending_config",
                    0x87c
                ),
                ("core::fmt::write", 8),
            ]
        );
    }

    #[test]
    fn a_frame_over_budget_fails_the_check_and_is_named() {
        let frames = frames_of(SNIPPET);
        let err = check_frames(&frames, FRAME_BUDGET_BYTES, &[])
            .unwrap_err()
            .to_string();
        assert!(err.contains("2 stack frame(s)"), "{err}");
        assert!(
            err.contains("71172 B (limit 8192 B) embassy_executor::raw::TaskStorage<F>::poll"),
            "{err}"
        );
        assert!(err.contains("big_by_register"), "{err}");
        assert!(!err.contains("apply_pending_config"), "{err}");
        assert!(check_frames(&frames[2..], FRAME_BUDGET_BYTES, &[]).is_ok());
        // An allowance lifts one function's limit, and only up to its ceiling.
        let allow = [
            ("big_by_register", 0x1_2345),
            ("TaskStorage<F>::poll", 0x11603),
        ];
        let err = check_frames(&frames, FRAME_BUDGET_BYTES, &allow)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("1 stack frame(s)") && err.contains("poll"),
            "{err}"
        );
        let allow = [
            ("big_by_register", 0x1_2345),
            ("TaskStorage<F>::poll", 0x11604),
        ];
        assert!(check_frames(&frames, FRAME_BUDGET_BYTES, &allow).is_ok());
        // The galvo task's 71 KB poll frame (the boot defect) fails the real check.
        assert!(check_frames(&frames[1..2], FRAME_BUDGET_BYTES, &FRAME_ALLOWANCES).is_err());
    }
}
