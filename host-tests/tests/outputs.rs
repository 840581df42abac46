//! The one output rule ([`impact_host::output`]): no output over an input, whatever path leads
//! there; every output whole or not at all, also with two writers at once; the figure and the
//! emulator in memory that does not grow with the recording; a file-size limit an error, not
//! a kill; an interrupt leaves no temporary file and no QEMU behind.

use std::path::Path;
use std::process::{Command, Stdio};

mod common;
use common::{impact_ok, Scratch};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The seed-001 impact as a CSV (its `impact synth`).
fn seed(path: &Path) {
    let (csv, _) = impact_ok(&common::SYNTH_T2);
    std::fs::write(path, csv).unwrap();
}

/// Raw i16 counts, `n` samples at rest (1000 ± 1) with a 2 ms half-sine of 1000 counts every
/// 100 000 samples (500 kS/s).
fn raw(path: &Path, n: usize) {
    let period = common::impact_period(100_000, 1000);
    let mut bytes = Vec::with_capacity(2 * n);
    while bytes.len() < 2 * n {
        let take = (2 * n - bytes.len()).min(period.len());
        bytes.extend_from_slice(&period[..take]);
    }
    std::fs::write(path, bytes).unwrap();
}

/// A refusal before any work: exit 1, the message, and every input as it was.
fn refused(args: &[&str], stdin: Option<&Path>, want: &str, inputs: &[&Path]) {
    let before: Vec<Vec<u8>> = inputs.iter().map(|p| std::fs::read(p).unwrap()).collect();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_impact"));
    cmd.args(args);
    if let Some(f) = stdin {
        cmd.stdin(std::fs::File::open(f).unwrap());
    }
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(err.contains(want), "{args:?}: {err}");
    for (p, b) in inputs.iter().zip(&before) {
        assert_eq!(
            &std::fs::read(p).unwrap(),
            b,
            "{args:?}: {} changed",
            p.display()
        );
    }
}

#[test]
fn no_output_writes_over_an_input_whatever_the_path() {
    let scratch = Scratch::new();
    let d = scratch.path();
    let csv = d.join("seed.csv");
    seed(&csv);
    let scene = d.join("scene.json");
    std::fs::write(&scene, r#"{"mass": 0.06, "v0": 1.3357}"#).unwrap();
    let hard = d.join("hard.svg");
    std::fs::hard_link(&csv, &hard).unwrap();
    let soft = d.join("soft.svg");
    std::os::unix::fs::symlink(&csv, &soft).unwrap();
    // The scene file written as a figure (named .svg: the name is no protection).
    let scene_svg = d.join("scene.svg");
    std::fs::write(&scene_svg, r#"{"mass": 0.06}"#).unwrap();
    let over = "would be overwritten";
    for (args, stdin) in [
        (
            vec![
                "analyze",
                s(&csv),
                "--scene",
                s(&scene_svg),
                "--plot",
                s(&scene_svg),
            ],
            None,
        ),
        (
            vec![
                "analyze",
                s(&csv),
                "--free-fall",
                s(&hard),
                "--plot",
                s(&hard),
            ],
            None,
        ),
        (vec!["analyze", s(&csv), "--plot", s(&hard)], None),
        (vec!["analyze", s(&csv), "--plot", s(&soft)], None),
        (
            vec!["analyze", "-", "--plot", s(&hard)],
            Some(csv.as_path()),
        ),
    ] {
        refused(&args, stdin, over, &[&csv, &scene_svg]);
    }
    // The emulator's figure, log and defmt stream, onto the recording or the firmware.
    let elf = d.join("firmware.elf");
    std::fs::write(&elf, b"\x7fELF not really").unwrap();
    for args in [
        vec!["emulate", s(&csv), "--log", s(&csv)],
        vec!["emulate", s(&csv), "--defmt", s(&hard)],
        vec!["emulate", s(&csv), "--elf", s(&elf), "--defmt", s(&elf)],
        vec!["emulate", s(&csv), "--scene", s(&scene), "--log", s(&scene)],
    ] {
        refused(&args, None, over, &[&csv, &elf, &scene]);
    }
    // A simulation's figure onto its target file.
    let target = d.join("mount.svg");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/mount.json"),
        &target,
    )
    .unwrap();
    refused(
        &[
            "simulate",
            "--model",
            "linear",
            "--mass",
            "0.06",
            "--v0",
            "1",
            "--stiffness",
            "1e4",
            "--target",
            s(&target),
            "--plot",
            s(&target),
        ],
        None,
        over,
        &[&target],
    );
    // A log's exported windows are numbered (`w.csv` gives `w-0.csv`): the numbered name is
    // checked, read from a file or on standard input.
    let log = d.join("w-0.csv");
    std::fs::write(
        &log,
        "0.01 INFO  scene rate_hz=10000.0 gain_m_s2_per_count=0.003210449 mass_kg=0.06 \
         v0_m_s=1.3357 drop_height_m=none trigger_m_s2=4.7 edge_m_s2=1.2 hold_s=0.002 \
         max_impact_s=1.0 settle_s=0.05 clip_low=-32768 clip_high=32767 cfc=none \
         trigger_cfc=none two_phase=true nonlinear=true fit_exponent=true exponent=1.0 \
         hertz=true train=none gravity_m_s2=none max_flight_s=none srs=false wave_every=1\n\
         0.1 INFO  wave seq=0 index=0 first_sample=0 samples=4 every=1 frames=1 base_sum=0 base_n=1\n\
         0.2 INFO  wave_frame seq=1 index=0 frame=0 counts=[1, 2, 3, 4]\n",
    )
    .unwrap();
    let export = d.join("w.csv");
    refused(
        &["log", s(&log), "--export", s(&export)],
        None,
        over,
        &[&log],
    );
    refused(
        &["log", "-", "--export", s(&export)],
        Some(log.as_path()),
        over,
        &[&log],
    );
    // Another name is written, whole.
    let (_, err) = impact_ok(&["log", s(&log), "--export", s(&d.join("x.wav"))]);
    assert!(err.contains("x-0.wav"), "{err}");
    assert_eq!(std::fs::read(d.join("x-0.wav")).unwrap().len(), 44 + 2 * 4);
}

/// An output over an existing file keeps that file's mode (a private 0600 figure stays private,
/// a 0664 one group-writable); a new one gets 0666 less the umask, as any tool's; a file this
/// user may not write (a 0444 copy kept as signed) is refused, unchanged, with the fix.
#[test]
fn an_output_keeps_the_targets_mode_and_a_read_only_target_is_refused() {
    use std::os::unix::fs::PermissionsExt;
    let scratch = Scratch::new();
    let d = scratch.path();
    let csv = d.join("seed.csv");
    seed(&csv);
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o7777;
    let chmod = |p: &Path, m: u32| {
        std::fs::set_permissions(p, std::fs::Permissions::from_mode(m)).unwrap();
    };
    for kept in [0o600, 0o640, 0o664] {
        let fig = d.join(format!("kept{kept:o}.svg"));
        std::fs::write(&fig, "old").unwrap();
        chmod(&fig, kept);
        impact_ok(&["analyze", s(&csv), "--plot", s(&fig)]);
        assert_ne!(std::fs::read(&fig).unwrap(), b"old");
        assert_eq!(mode(&fig), kept, "{}", fig.display());
    }
    // A new file under umask 077 (a shell's `umask 077`): 0600, not the 0644 it used to get.
    let new = d.join("new.svg");
    let out = Command::new("sh")
        .args(["-c", "umask 077 && exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_impact"))
        .args(["analyze", s(&csv), "--plot", s(&new)])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(mode(&new), 0o600);
    // Read-only: refused before any work, the file as it was.
    let signed = d.join("signed.svg");
    std::fs::write(&signed, "signed").unwrap();
    chmod(&signed, 0o444);
    // No write bit at all is refused for every user, root too (as `rm` asks).
    refused(
        &["analyze", s(&csv), "--plot", s(&signed)],
        None,
        "read-only; it is not replaced",
        &[&csv, &signed],
    );
    assert_eq!(mode(&signed), 0o444);
    // Setuid and setgid are not carried to a file this user now owns: the permission bits are.
    let suid = d.join("suid.svg");
    std::fs::write(&suid, "old").unwrap();
    chmod(&suid, 0o6755);
    impact_ok(&["analyze", s(&csv), "--plot", s(&suid)]);
    assert_eq!(mode(&suid), 0o755);
    // A FIFO (as a device such as /dev/null would be) is no file to rename over: refused,
    // left a FIFO (as root, `--plot /dev/null` replaced the device with a regular file).
    let fifo = d.join("fifo.svg");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    refused(
        &["analyze", s(&csv), "--plot", s(&fifo)],
        None,
        "is not a regular file (a device, a FIFO or a socket)",
        &[&csv],
    );
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

#[test]
fn two_writers_of_one_figure_leave_one_whole_figure() {
    let scratch = Scratch::new();
    let d = scratch.path();
    let csv = d.join("seed.csv");
    seed(&csv);
    let svg = d.join("both.svg");
    for _ in 0..6 {
        let spawn = || {
            Command::new(env!("CARGO_BIN_EXE_impact"))
                .args([
                    "analyze",
                    s(&csv),
                    "--mass",
                    "0.06",
                    "--v0",
                    "1.3357",
                    "--plot",
                    s(&svg),
                ])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap()
        };
        let (mut a, mut b) = (spawn(), spawn());
        assert!(a.wait().unwrap().success() && b.wait().unwrap().success());
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    }
    let left: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".part"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// `impact ARGS` with its own peak memory printed: (stdout, stderr, MiB).
fn measured(args: &[&str]) -> (String, String, f64) {
    let out = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(args)
        .env("IMPACT_PEAK_MEMORY", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?}: {err}");
    let mib = common::peak_memory_mib(&err);
    (String::from_utf8_lossy(&out.stdout).into_owned(), err, mib)
}

#[test]
fn the_figure_and_the_emulator_hold_no_whole_recording() {
    // 2^23 samples (16 MB of i16; held whole with its values, some 200 MB): the figure
    // reads its windows in a last pass, the emulator gets the counts through a file written a
    // block at a time. Both give the reports of the analysis in passes.
    let scratch = Scratch::new();
    let d = scratch.path();
    let big = d.join("big.i16");
    raw(&big, 1 << 23);
    let svg = d.join("big.svg");
    let (plain, _, _) = measured(&["analyze", s(&big), "--rate", "500000", "--json"]);
    let (with_plot, err, mib) = measured(&[
        "analyze",
        s(&big),
        "--rate",
        "500000",
        "--json",
        "--plot",
        s(&svg),
    ]);
    assert_eq!(with_plot, plain);
    assert!(mib < 48.0, "analyze --plot: {mib:.0} MiB");
    assert!(err.contains("the figure shows the first 6 of"), "{err}");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.len() < 1_000_000, "{} bytes", text.len());
    if impact_host::firmware_link::qemu::tools_available().is_err() {
        assert!(std::env::var_os("IMPACT_REQUIRE_EMULATOR").is_none());
        return;
    }
    let (emulated, _, mib) = measured(&["emulate", s(&big), "--rate", "500000", "--json"]);
    assert!(mib < 48.0, "emulate: {mib:.0} MiB");
    let impacts = |json: &str| {
        let v: serde_json::Value = serde_json::from_str(json).unwrap();
        v["impacts"].as_array().unwrap().len()
    };
    assert_eq!(impacts(&emulated), impacts(&plain));
    assert!(impacts(&plain) >= 80);
}

#[test]
fn a_file_size_limit_is_a_message_never_a_kill() {
    // `ulimit -f`: the spool of a CSV's values (a temporary file) and a figure exceed it.
    use std::os::unix::process::CommandExt;
    let scratch = Scratch::new();
    let d = scratch.path();
    let csv = d.join("seed.csv");
    seed(&csv);
    let run = |args: &[&str]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_impact"));
        cmd.args(args);
        // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
        unsafe {
            cmd.pre_exec(|| {
                let limit = libc::rlimit {
                    rlim_cur: 64 * 1024,
                    rlim_max: 64 * 1024,
                };
                libc::setrlimit(libc::RLIMIT_FSIZE, &limit);
                Ok(())
            });
        }
        cmd.output().unwrap()
    };
    let out = run(&["analyze", s(&csv)]);
    assert!(out.status.success(), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("read again"), "{err}");
    let svg = d.join("large.svg");
    let out = run(&[
        "analyze",
        s(&csv),
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
        "--plot",
        s(&svg),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("large.svg") && err.contains("too large"),
        "{err}"
    );
    assert!(!svg.exists());
    assert!(std::fs::read_dir(d).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .ends_with(".part")));
}

#[test]
fn an_interrupt_removes_the_temporary_files_and_ends_qemu() {
    if impact_host::firmware_link::qemu::tools_available().is_err() {
        assert!(std::env::var_os("IMPACT_REQUIRE_EMULATOR").is_none());
        return;
    }
    let scratch = Scratch::new();
    let d = scratch.path();
    let tmp = d.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let big = d.join("long.i16");
    raw(&big, 1 << 23);
    // Real time at a tenth of the rate: 168 s of emulation; interrupted after two.
    let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args([
            "emulate",
            s(&big),
            "--rate",
            "500000",
            "--realtime",
            "--rate-scale",
            "0.1",
        ])
        .env("TMPDIR", &tmp)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_secs(2));
    let qemu_running = || {
        std::fs::read_dir("/proc")
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| {
                std::fs::read(e.path().join("cmdline"))
                    .is_ok_and(|c| String::from_utf8_lossy(&c).contains(s(&tmp)))
            })
    };
    assert!(qemu_running(), "QEMU started");
    assert!(
        std::fs::read_dir(&tmp).unwrap().count() > 0,
        "its recording in TMPDIR"
    );
    // SIGINT to the tool alone (not its process group: QEMU does not get it).
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let status = child.wait().unwrap();
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    use std::os::unix::process::ExitStatusExt;
    assert_eq!(status.signal(), Some(libc::SIGINT), "{status:?}: {err}");
    assert!(err.contains("interrupted"), "{err}");
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert!(!qemu_running(), "QEMU ended");
    let left: Vec<_> = std::fs::read_dir(&tmp).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}
