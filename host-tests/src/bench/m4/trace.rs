//! QEMU runs of the m4-bench firmware: the executed instructions between the marks
//! (`-singlestep -d exec,nochain`), weighed by [`super::cycles`], and the per-function
//! profile.

use std::collections::HashMap;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

use super::cycles::cycles;
use super::disasm::Code;
use super::M4Error;

/// Counts of one measured region.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Region {
    pub(super) instructions: u64,
    pub(super) cycles: u64,
}

/// Runs `qemu-system-arm` on the bench ELF; returns its standard output. With `trace`, every
/// executed instruction is logged into a FIFO read by `on_line`.
pub(super) fn run_qemu(
    elf: &Path,
    args: &[String],
    trace: Option<&mut dyn FnMut(&str)>,
    icount: bool,
) -> Result<String, M4Error> {
    let qemu = |source| M4Error::Tool {
        tool: "qemu-system-arm",
        source,
    };
    let dir = std::env::temp_dir().join(format!("impact-m4-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(super::file(&dir))?;
    let _dir = crate::interrupt::temporary(&dir);
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args([
        "-machine",
        "mps2-an386",
        "-cpu",
        "cortex-m4",
        "-nographic",
        "-monitor",
        "none",
        "-serial",
        "null",
    ]);
    let mut config = String::from("enable=on,target=native,arg=firmware");
    for a in args {
        config.push_str(",arg=");
        config.push_str(a);
    }
    cmd.args(["-semihosting-config", &config]);
    cmd.arg("-kernel").arg(elf);
    cmd.stdout(Stdio::piped()).stderr(Stdio::piped());
    if icount {
        cmd.args(["-icount", "shift=0"]);
    }
    let fifo = dir.join("trace.fifo");
    // Removed, and QEMU ended, on an interrupt.
    let _fifo = crate::interrupt::temporary(&fifo);
    let result = match trace {
        None => cmd
            .spawn()
            .and_then(|child| {
                let _child = crate::interrupt::child(child.id());
                child.wait_with_output()
            })
            .map_err(qemu),
        Some(on_line) => {
            let _ = std::fs::remove_file(&fifo);
            let status = Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .map_err(|source| M4Error::Tool {
                    tool: "mkfifo",
                    source,
                })?;
            if !status.success() {
                return Err(M4Error::Mkfifo { fifo });
            }
            cmd.args(["-singlestep", "-d", "exec,nochain", "-D"])
                .arg(&fifo);
            let child = cmd.spawn().map_err(qemu)?;
            let _child = crate::interrupt::child(child.id());
            // QEMU opens the log when it starts; the FIFO blocks until then.
            let file = std::fs::File::open(&fifo).map_err(super::file(&fifo))?;
            let mut reader = BufReader::with_capacity(1 << 20, file);
            let mut line = String::new();
            loop {
                line.clear();
                match reader.read_line(&mut line) {
                    Ok(0) => break,
                    Ok(_) => on_line(&line),
                    Err(e) => return Err(M4Error::Trace(e)),
                }
            }
            child.wait_with_output().map_err(qemu)
        }
    };
    let _ = std::fs::remove_file(&fifo);
    let _ = std::fs::remove_dir(&dir);
    let out = result?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() || stdout.lines().any(|l| l.starts_with("error")) {
        return Err(M4Error::Failed {
            status: out.status,
            output: stdout + &String::from_utf8_lossy(&out.stderr),
        });
    }
    Ok(stdout)
}

/// Walks the trace: counts the instructions between the marks.
#[derive(Default)]
pub(super) struct TraceState {
    /// Inside a measured region.
    pub(super) counting: bool,
    /// Inside `bench_begin` (the region starts when it returns).
    pub(super) in_begin: bool,
    pub(super) current: Region,
    /// The last counted instruction, whose cycles wait for the next address.
    pub(super) prev: Option<u32>,
    pub(super) after_load: bool,
    pub(super) symbols: HashMap<String, u64>,
}

impl TraceState {
    pub(super) fn line(
        &mut self,
        line: &str,
        code: &Code,
        regions: &mut Vec<Region>,
        profile: &mut Vec<HashMap<String, u64>>,
        keep_profile: bool,
    ) {
        // `Trace 0: 0x7ff9dc000100 [00800408/00000400/00000110/ff000201] Reset`
        let Some(pc) = line
            .split_once('[')
            .and_then(|(_, r)| r.split('/').nth(1))
            .and_then(|p| u32::from_str_radix(p, 16).ok())
        else {
            return;
        };
        let inside = |r: (u32, u32)| pc >= r.0 && pc < r.1;
        if inside(code.begin) {
            self.in_begin = true;
            self.counting = false;
            self.prev = None;
            return;
        }
        if self.in_begin {
            self.in_begin = false;
            self.counting = true;
            self.current = Region::default();
            self.after_load = false;
            self.symbols.clear();
        }
        if pc == code.end.0 && self.counting {
            // The previous instruction (the call) is counted; close it.
            self.close_prev(pc, code);
            self.counting = false;
            regions.push(self.current);
            if keep_profile {
                profile.push(std::mem::take(&mut self.symbols));
            }
            return;
        }
        if !self.counting {
            return;
        }
        self.close_prev(pc, code);
        self.prev = Some(pc);
        self.current.instructions += 1;
        if keep_profile {
            let sym = line.rsplit(' ').next().unwrap_or("?").trim().to_string();
            *self.symbols.entry(sym).or_default() += 1;
        }
    }

    /// Adds the cycles of the previous instruction, now that the next address is known.
    pub(super) fn close_prev(&mut self, next_pc: u32, code: &Code) {
        if let Some(pc) = self.prev.take() {
            if let Some(insn) = code.insns.get(&pc) {
                let taken = next_pc != pc + insn.size;
                self.current.cycles += cycles(insn, taken, self.after_load) as u64;
                let base = insn.mnemonic.split('.').next().unwrap_or("");
                self.after_load = base.starts_with("ldr") && !base.starts_with("ldrd");
            } else {
                self.current.cycles += 1;
                self.after_load = false;
            }
        }
    }
}

pub(super) fn profile_text(kinds: &str, profile: &[HashMap<String, u64>]) -> String {
    let mut out = String::new();
    for (kind, name) in [
        ('i', "idle"),
        ('t', "trigger"),
        ('a', "in impact"),
        ('e', "end (report)"),
    ] {
        let mut sum: HashMap<&str, u64> = HashMap::new();
        for (k, p) in kinds.chars().zip(profile) {
            if k == kind {
                for (s, n) in p {
                    *sum.entry(s.as_str()).or_default() += n;
                }
            }
        }
        let mut v: Vec<_> = sum.into_iter().collect();
        v.sort_by_key(|e| std::cmp::Reverse(e.1));
        out.push_str(&format!("{name}:\n"));
        for (s, n) in v.into_iter().take(8) {
            out.push_str(&format!("  {n:>10}  {s}\n"));
        }
    }
    out
}
