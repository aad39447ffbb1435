//! `cargo xtask bench`: a fixed set of measurements (criterion benches, the correction latency
//! harness and an end-to-end `ridi demo`) run as subprocesses, collected into a JSON report and
//! `docs/bench-latest.md`, and compared with the baseline of the CPU it runs on
//! (`benchmarks/baseline.json`, or `benchmarks/baseline-<cpu model>.json`: [`baseline_for`]).
//!
//! The machine is shared with other builds, so the comparison uses CPU-time figures only, each
//! divided by a reference figure measured in the same run (the naive feature extraction): a
//! regression is a normalized figure more than [`TOLERANCE`] above the baseline's. Wall-clock
//! figures are reported but not compared.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};

/// The reference figure: every compared figure is divided by it.
pub const REFERENCE: &str = "features/naive_tenth_cpu";
/// A normalized figure more than this fraction above the baseline's fails the comparison.
pub const TOLERANCE: f64 = 0.20;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Figure {
    pub name: String,
    pub value: f64,
    pub unit: String,
    /// CPU-time figure, compared with the baseline (wall-clock figures are informational).
    pub compared: bool,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Machine {
    pub cpus: usize,
    pub model: String,
    pub memory: String,
    pub load_average: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Report {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    pub machine: Machine,
    pub commit: String,
    pub command: String,
    pub reference: String,
    pub figures: Vec<Figure>,
}

/// One compared figure: both normalized values and their ratio (now / baseline).
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    pub name: String,
    pub baseline: f64,
    pub now: f64,
    pub ratio: f64,
    pub regressed: bool,
}

pub struct Options {
    pub quick: bool,
    pub json: Option<PathBuf>,
    pub update_baseline: bool,
}

/// A criterion measurement: the bench target, a filter, and the figures it yields.
struct CriterionRun {
    package: &'static str,
    bench: &'static str,
    filter: &'static str,
    /// (figure name, criterion group, bench id, compared).
    figures: &'static [(&'static str, &'static str, &'static str, bool)],
    quick: bool,
}

const CRITERION: &[CriterionRun] = &[
    CriterionRun {
        package: "ridi-features",
        bench: "features",
        filter: "^cpu_1t/(naive_tenth|windows_reuse)$",
        figures: &[
            (REFERENCE, "cpu_1t", "naive_tenth", true),
            (
                "features/windows_reuse_cpu",
                "cpu_1t",
                "windows_reuse",
                true,
            ),
        ],
        quick: true,
    },
    CriterionRun {
        package: "ridi-data",
        bench: "read",
        filter: "^ridi_data_120k_rows_cpu/read_csv$",
        figures: &[(
            "data/read_csv_120k_cpu",
            "ridi_data_120k_rows_cpu",
            "read_csv",
            true,
        )],
        quick: true,
    },
    CriterionRun {
        package: "ridi-regress",
        bench: "svr",
        filter: "^regress/(gram_2000x1200|svr_fit_2000_c10_eps0.01|cascade_predict_one)$",
        figures: &[
            (
                "regress/gram_2000x1200_wall",
                "regress",
                "gram_2000x1200",
                false,
            ),
            (
                "regress/svr_fit_2000_wall",
                "regress",
                "svr_fit_2000_c10_eps0.01",
                false,
            ),
            (
                "regress/cascade_predict_one_wall",
                "regress",
                "cascade_predict_one",
                false,
            ),
        ],
        quick: false,
    },
];

pub fn run(opts: Options) -> Result<()> {
    let root = xtask::workspace_root();
    let target = target_dir(&root);
    let started = Instant::now();
    let mut figures = Vec::new();
    let (warm, measure) = if opts.quick { ("0.5", "1") } else { ("2", "5") };

    for c in CRITERION.iter().filter(|c| c.quick || !opts.quick) {
        eprintln!("bench: {} --bench {} ({})", c.package, c.bench, c.filter);
        let args = [
            "bench",
            "-p",
            c.package,
            "--bench",
            c.bench,
            "--",
            c.filter,
            "--noplot",
            "--warm-up-time",
            warm,
            "--measurement-time",
            measure,
        ];
        cargo(&root, &args)?;
        for &(name, group, id, compared) in c.figures {
            let ns = read_estimate(&target.join("criterion"), group, id)?;
            figures.push(figure(name, ns / 1e6, "ms", compared));
        }
    }

    eprintln!("bench: ridi-correct --bench latency");
    let out = cargo(
        &root,
        &["bench", "-p", "ridi-correct", "--bench", "latency"],
    )?;
    figures.extend(parse_latency(&out)?);

    eprintln!("bench: ridi demo");
    cargo(&root, &["build", "--release", "-p", "ridi-cli"])?;
    figures.extend(time_demo(&target.join("release/ridi"), &root, opts.quick)?);

    // The accuracy protocol's reference variant, where the Tyrex data are present (full mode).
    let shared = root.join(xtask::DEFAULT_TYREX);
    if !opts.quick && shared.is_dir() {
        eprintln!("bench: accuracy protocol (eval tyrex --quick)");
        let out = target.join("bench-accuracy.md");
        crate::eval_tyrex::run(Some(shared), Some(out.clone()), true, None)?;
        eprintln!("bench: accuracy report in {}", out.display());
    }

    let mut command = String::from("cargo xtask bench");
    if opts.quick {
        command.push_str(" --quick");
    }
    let report = Report {
        note: None,
        machine: machine(),
        commit: git_commit(&root),
        command,
        reference: REFERENCE.into(),
        figures,
    };
    let json = opts
        .json
        .unwrap_or_else(|| target.join("bench-report.json"));
    write_json(&json, &report)?;
    println!(
        "wrote {} ({:.0} s)",
        json.display(),
        started.elapsed().as_secs_f64()
    );

    let baseline_path = baseline_for(&root, &report.machine.model, opts.update_baseline)?;
    let shown = baseline_path
        .strip_prefix(&root)
        .unwrap_or(&baseline_path)
        .display()
        .to_string();
    let comparisons = if opts.update_baseline {
        let mut base = report.clone();
        base.note = Some(format!(
            "Produced by `{} --update-baseline`. The machine was shared with other builds \
             while measuring: only CPU-time figures, divided by {REFERENCE} from the same run, \
             are compared.",
            report.command
        ));
        write_json(&baseline_path, &base)?;
        println!("wrote {shown}");
        Vec::new()
    } else {
        let text = std::fs::read_to_string(&baseline_path)
            .with_context(|| format!("reading {}", baseline_path.display()))?;
        let base: Report = serde_json::from_str(&text)
            .with_context(|| format!("parsing {}", baseline_path.display()))?;
        println!("baseline: {shown} ({})", base.machine.model);
        compare(&base.figures, &report.figures, REFERENCE, TOLERANCE)?
    };

    let md = markdown(&report, &comparisons, &shown);
    let md_path = root.join("docs/bench-latest.md");
    ridi_data::write_atomically(&md_path, |w| w.write_all(md.as_bytes()))?;
    println!("wrote {}", md_path.display());

    for c in &comparisons {
        println!(
            "{:<36} normalized {:>10} baseline {:>10} ratio {:.3}{}",
            c.name,
            significant(c.now),
            significant(c.baseline),
            c.ratio,
            if c.regressed { "  REGRESSED" } else { "" }
        );
    }
    check(&comparisons, &shown)
}

/// The baseline for a CPU of model `model`: `benchmarks/baseline-<model>.json` when one was
/// recorded on that model, else `benchmarks/baseline.json`, which a comparison uses whatever
/// its CPU (`.ci/bench` then reports without failing). `--update-baseline` (`update`) writes
/// `baseline.json` when it does not exist or was recorded on this model, else this model's
/// own file. A normalized figure holds for the CPU it was measured on only
/// (docs/benchmarks.md, "On another CPU").
pub fn baseline_for(root: &Path, model: &str, update: bool) -> Result<PathBuf> {
    let dir = root.join("benchmarks");
    let own = dir.join(format!("baseline-{}.json", slug(model)));
    let main = dir.join("baseline.json");
    if own.is_file() {
        return Ok(own);
    }
    if !update {
        return Ok(main);
    }
    let text = match std::fs::read_to_string(&main) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(main),
        // Never written over when it cannot be read: it may be another CPU's.
        Err(e) => return Err(e).with_context(|| format!("reading {}", main.display())),
    };
    let base: Report =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", main.display()))?;
    // The same name only (spacing, case and punctuation aside): a recorded "AMD EPYC" says
    // nothing of the generation, so an "AMD EPYC 7763" records into its own file rather than
    // over it. A name without letters or digits (none in /proc/cpuinfo) is nobody's.
    let recorded = slug(&base.machine.model);
    Ok(if recorded != UNKNOWN_CPU && recorded == slug(model) {
        main
    } else {
        own
    })
}

/// [`slug`] of a CPU model name without letters or digits.
const UNKNOWN_CPU: &str = "unknown-cpu";

/// `model` as a file name part: lowercase ASCII letters and digits, runs of anything else one
/// `-` ("Intel(R) Xeon(R) Processor" -> "intel-r-xeon-r-processor").
fn slug(model: &str) -> String {
    let mut out = String::new();
    for c in model.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('-') {
            out.push('-');
        }
    }
    let out = out.trim_end_matches('-');
    if out.is_empty() {
        UNKNOWN_CPU.into()
    } else {
        out.into()
    }
}

/// Fails, naming each figure, when a comparison against the baseline `baseline` regressed.
pub fn check(comparisons: &[Comparison], baseline: &str) -> Result<()> {
    let regressed: Vec<String> = comparisons
        .iter()
        .filter(|c| c.regressed)
        .map(|c| format!("{} ({:+.0} %)", c.name, (c.ratio - 1.0) * 100.0))
        .collect();
    if !regressed.is_empty() {
        bail!(
            "slower than {baseline} by more than {:.0} % (normalized by {REFERENCE}): {}",
            TOLERANCE * 100.0,
            regressed.join(", ")
        );
    }
    Ok(())
}

fn figure(name: &str, value: f64, unit: &str, compared: bool) -> Figure {
    Figure {
        name: name.into(),
        value,
        unit: unit.into(),
        compared,
    }
}

/// `CARGO_TARGET_DIR` (relative to the current directory) or `<workspace>/target`.
fn target_dir(root: &Path) -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(d) if !d.is_empty() => {
            let d = PathBuf::from(d);
            if d.is_absolute() {
                d
            } else {
                std::env::current_dir().map(|c| c.join(&d)).unwrap_or(d)
            }
        }
        _ => root.join("target"),
    }
}

/// Runs cargo in the workspace; returns its stdout (stderr goes to the terminal).
fn cargo(root: &Path, args: &[&str]) -> Result<String> {
    let target = target_dir(root);
    let stdout = xtask::cargo_stdout(root, args, &[("CARGO_TARGET_DIR", &target)])?;
    print!("{stdout}");
    Ok(stdout)
}

/// Criterion's directory name for an id: characters unsafe in file names become `_`.
fn criterion_dir_name(id: &str) -> String {
    id.chars()
        .map(|c| match c {
            '?' | '"' | '/' | '\\' | '*' | '<' | '>' | ':' | '|' | '^' => '_',
            c => c,
        })
        .collect()
}

/// Mean point estimate (ns) of `<criterion>/<group>/<id>/new/estimates.json`.
pub fn read_estimate(criterion: &Path, group: &str, id: &str) -> Result<f64> {
    let path = criterion
        .join(criterion_dir_name(group))
        .join(criterion_dir_name(id))
        .join("new/estimates.json");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    v["mean"]["point_estimate"]
        .as_f64()
        .with_context(|| format!("{}: no mean.point_estimate", path.display()))
}

/// The number following `key` in `line` (up to a space or comma).
fn number_after(line: &str, key: &str) -> Option<f64> {
    let rest = &line[line.find(key)? + key.len()..];
    let token = rest.split([' ', ',', ')']).find(|t| !t.is_empty())?;
    token.parse().ok()
}

/// Figures from the stdout of `cargo bench -p ridi-correct --bench latency`.
pub fn parse_latency(out: &str) -> Result<Vec<Figure>> {
    let mut figures = Vec::new();
    for line in out.lines() {
        if line.starts_with("10-minute global solve: ") {
            if let Some(v) = number_after(line, "CPU ") {
                figures.push(figure("correct/global_10min_cpu", v, "ms", true));
            }
            if let Some(v) = number_after(line, "wall ") {
                figures.push(figure("correct/global_10min_wall", v, "ms", false));
            }
        } else if line.starts_with("1000-frame window solve: ") {
            if let Some(v) = number_after(line, "CPU ") {
                figures.push(figure("correct/window_1000_cpu", v, "ms", true));
            }
        } else if line.starts_with("1000-frame window solve, wall per call") {
            if let Some(v) = number_after(line, "p99 ") {
                figures.push(figure("correct/window_1000_p99_wall", v, "ms", false));
            }
        } else if line.starts_with("update latency (inline)") {
            // "correcting frames n=594 p50=0.0488 ms p99=0.0711 ms ...": the streaming update
            // that includes a window correction, the one that matters for latency.
            if let Some(v) = number_after(line, "p50=") {
                figures.push(figure("correct/update_p50_wall", v, "ms", false));
            }
            if let Some(v) = number_after(line, "p99=") {
                figures.push(figure("correct/update_p99_wall", v, "ms", false));
            }
        } else if line.starts_with("one-hour stream (inline)") {
            let frames = number_after(line, "one-hour stream (inline): ");
            if let (Some(n), Some(cpu)) = (frames, number_after(line, "calling thread CPU ")) {
                figures.push(figure(
                    "correct/stream_inline_cpu",
                    cpu * 1e9 / n,
                    "ns/frame",
                    true,
                ));
            }
        }
    }
    if figures.is_empty() {
        bail!("no figures in the output of the latency bench");
    }
    Ok(figures)
}

/// CPU seconds of the waited-for children of this process (`/proc/self/stat`, 100 Hz ticks).
fn children_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = s.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(13)? + ticks(14)?) / 100.0)
}

/// Runs `cmd` to completion: wall seconds and peak resident memory (VmHWM, KiB, sampled every
/// 5 ms from /proc while it runs; VmHWM only grows, so the last sample is the peak up to then).
fn run_measured(cmd: &mut Command) -> Result<(f64, Option<f64>)> {
    let t0 = Instant::now();
    let mut child = cmd
        .stdout(std::process::Stdio::null())
        .spawn()
        .context("starting a ridi command")?;
    let status_file = format!("/proc/{}/status", child.id());
    let mut peak = None;
    let status = loop {
        if let Some(kb) = std::fs::read_to_string(&status_file).ok().and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        }) {
            peak = Some(kb);
        }
        if let Some(status) = child.try_wait()? {
            break status;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    if !status.success() {
        bail!("{cmd:?} failed: {status}");
    }
    Ok((t0.elapsed().as_secs_f64(), peak))
}

/// End-to-end figures with the built `ridi` binary on the bundled sample: `ridi demo` (train
/// 16 runs without grid search, evaluate 10), with `--grid small` in full mode, and tracking
/// throughput, batch and streaming, with the demo's model on one 24 s run.
fn time_demo(ridi: &Path, root: &Path, quick: bool) -> Result<Vec<Figure>> {
    let out = tempfile::tempdir()?;
    let c0 = children_cpu_seconds();
    let (wall, peak) = run_measured(
        Command::new(ridi)
            .args(["demo", "--plots", "none", "--out"])
            .arg(out.path()),
    )?;
    let mut figures = vec![figure("e2e/demo_wall", wall, "s", false)];
    if let (Some(a), Some(b)) = (c0, children_cpu_seconds()) {
        figures.push(figure("e2e/demo_cpu", b - a, "s", true));
    }
    if let Some(kb) = peak {
        figures.push(figure("e2e/demo_peak_rss", kb / 1024.0, "MiB", false));
    }
    if !quick {
        let grid_out = tempfile::tempdir()?;
        let (wall, peak) = run_measured(
            Command::new(ridi)
                .args(["demo", "--plots", "none", "--grid", "small", "--out"])
                .arg(grid_out.path()),
        )?;
        figures.push(figure("e2e/demo_grid_small_wall", wall, "s", false));
        if let Some(kb) = peak {
            figures.push(figure(
                "e2e/demo_grid_small_peak_rss",
                kb / 1024.0,
                "MiB",
                false,
            ));
        }
    }
    let run = root.join("datasets/sample/Thibaud_Nexus5_NoDist_Texting");
    let frames = 4800.0;
    for (mode, extra) in [("batch", None), ("online", Some("--online"))] {
        let mut cmd = Command::new(ridi);
        cmd.arg("track")
            .arg(&run)
            .arg("--model")
            .arg(out.path().join("model.ridi"))
            .arg("--out")
            .arg(out.path().join(format!("{mode}.csv")));
        if let Some(flag) = extra {
            cmd.arg(flag);
        }
        let (wall, peak) = run_measured(&mut cmd)?;
        figures.push(figure(
            &format!("e2e/track_{mode}_frames_per_s"),
            frames / wall,
            "frames/s",
            false,
        ));
        if let Some(kb) = peak {
            figures.push(figure(
                &format!("e2e/track_{mode}_peak_rss"),
                kb / 1024.0,
                "MiB",
                false,
            ));
        }
    }
    Ok(figures)
}

/// Compares the compared figures present in both runs, each divided by its run's `reference`.
pub fn compare(
    baseline: &[Figure],
    now: &[Figure],
    reference: &str,
    tolerance: f64,
) -> Result<Vec<Comparison>> {
    let find = |figs: &[Figure], name: &str| figs.iter().find(|f| f.name == name).map(|f| f.value);
    let (Some(base_ref), Some(now_ref)) = (find(baseline, reference), find(now, reference)) else {
        bail!("reference figure {reference} missing from the baseline or this run");
    };
    if base_ref <= 0.0 || now_ref <= 0.0 {
        bail!("reference figure {reference} is not positive");
    }
    Ok(now
        .iter()
        .filter(|f| f.compared && f.name != reference)
        .filter_map(|f| {
            let b = baseline.iter().find(|b| b.name == f.name && b.compared)?;
            let (base, cur) = (b.value / base_ref, f.value / now_ref);
            let ratio = cur / base;
            Some(Comparison {
                name: f.name.clone(),
                baseline: base,
                now: cur,
                ratio,
                regressed: ratio > 1.0 + tolerance,
            })
        })
        .collect())
}

fn machine() -> Machine {
    let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
    let field = |text: &str, key: &str| {
        text.lines()
            .find(|l| l.starts_with(key))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
            .unwrap_or_default()
    };
    let mem_kib: f64 = field(&read("/proc/meminfo"), "MemTotal")
        .trim_end_matches("kB")
        .trim()
        .parse()
        .unwrap_or(0.0);
    Machine {
        cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        model: field(&read("/proc/cpuinfo"), "model name"),
        memory: format!("{:.1} GiB", mem_kib / 1048576.0),
        load_average: read("/proc/loadavg")
            .split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" "),
    }
}

fn git_commit(root: &Path) -> String {
    Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

fn write_json(path: &Path, report: &Report) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    let mut text = serde_json::to_string_pretty(report)?;
    text.push('\n');
    ridi_data::write_atomically(path, |w| w.write_all(text.as_bytes()))?;
    Ok(())
}

/// Four significant digits.
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

pub fn markdown(report: &Report, comparisons: &[Comparison], baseline: &str) -> String {
    let m = &report.machine;
    let mut s = String::new();
    let _ = writeln!(s, "# Latest benchmark run\n");
    let _ = writeln!(
        s,
        "Written by `{}`; do not edit. Machine: {} CPUs ({}), {} RAM, load average {} at \
         the end. Commit `{}`.\n",
        report.command, m.cpus, m.model, m.memory, m.load_average, report.commit
    );
    let _ = writeln!(
        s,
        "CPU-time figures are divided by `{}` from the same run and compared with \
         `{baseline}` (fail above +{:.0} %); wall-clock figures are informational.\n",
        report.reference,
        TOLERANCE * 100.0
    );
    let _ = writeln!(s, "| figure | value | unit | normalized | vs baseline |");
    let _ = writeln!(s, "| --- | ---: | --- | ---: | ---: |");
    let reference = report
        .figures
        .iter()
        .find(|f| f.name == report.reference)
        .map(|f| f.value);
    for f in &report.figures {
        let norm = match (f.compared, reference) {
            (true, Some(r)) if r > 0.0 => significant(f.value / r),
            _ => "-".into(),
        };
        let vs = comparisons
            .iter()
            .find(|c| c.name == f.name)
            .map_or("-".into(), |c| {
                format!(
                    "{:+.1} %{}",
                    (c.ratio - 1.0) * 100.0,
                    if c.regressed { " REGRESSED" } else { "" }
                )
            });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            f.name,
            significant(f.value),
            f.unit,
            norm,
            vs
        );
    }
    let value = |name: &str| {
        report
            .figures
            .iter()
            .find(|f| f.name == name)
            .map_or("-".to_string(), |f| {
                format!("{} {}", significant(f.value), f.unit)
            })
    };
    let _ = writeln!(s, "\n## Beside the paper's figures (i7-4790)\n");
    let _ = writeln!(s, "| what | paper | this run |\n| --- | --- | --- |");
    let _ = writeln!(
        s,
        "| overall tracking throughput | 2,000 frames/s | {} batch, {} online (incl. reading the csv and the model) |",
        value("e2e/track_batch_frames_per_s"),
        value("e2e/track_online_frames_per_s")
    );
    let _ = writeln!(
        s,
        "| one online correction (1,000-frame window) | 15 ms | {} (CPU), p99 {} |",
        value("correct/window_1000_cpu"),
        value("correct/window_1000_p99_wall")
    );
    let _ = writeln!(
        s,
        "| one SVR regression | 19 ms | {} (whole cascade query, full mode only) |",
        value("regress/cascade_predict_one_wall")
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_criterion_estimates() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().join("global/10min_solve/new");
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(
            d.join("estimates.json"),
            r#"{"mean":{"confidence_interval":{"confidence_level":0.95,"lower_bound":1.0,"upper_bound":3.0},"point_estimate":2500000.5,"standard_error":1.0},"median":{"point_estimate":1.0}}"#,
        )
        .unwrap();
        let v = read_estimate(dir.path(), "global", "10min/solve").unwrap();
        assert_eq!(v, 2500000.5);
        assert!(read_estimate(dir.path(), "global", "missing").is_err());
    }

    #[test]
    fn parses_latency_lines() {
        let out = "one-hour stream (inline): 720000 frames in 0.430 s wall = 1.66 M frames/s (calling thread CPU 0.22 s = 3.30 M frames/s); corrections 1\n\
                   10-minute global solve: wall 5.950 ms, CPU 3.070 ms (mean of 300)\n\
                   10-minute global solve + integration: wall 9.000 ms, CPU 8.000 ms (mean of 100)\n\
                   1000-frame window solve: wall 0.0400 ms, CPU 0.0300 ms (mean of 20,000)\n\
                   1000-frame window solve, wall per call: p50 0.0300 ms, p99 0.0340 ms, p99.9 0.1 ms\n\
                   update latency (inline), 10 min stream: correcting frames n=594 p50=0.0488 ms p99=0.0711 ms max=0.0896 ms; other frames p50=0.00006 ms\n";
        let f = parse_latency(out).unwrap();
        let get = |n: &str| f.iter().find(|x| x.name == n).unwrap().value;
        assert_eq!(get("correct/global_10min_cpu"), 3.07);
        assert_eq!(get("correct/global_10min_wall"), 5.95);
        assert_eq!(get("correct/window_1000_cpu"), 0.03);
        assert_eq!(get("correct/window_1000_p99_wall"), 0.034);
        assert_eq!(get("correct/update_p50_wall"), 0.0488);
        assert_eq!(get("correct/update_p99_wall"), 0.0711);
        assert!((get("correct/stream_inline_cpu") - 0.22e9 / 720000.0).abs() < 1e-9);
        assert!(parse_latency("nothing").is_err());
    }

    #[test]
    fn comparison_uses_ratios_and_a_20_percent_threshold() {
        let base = vec![
            figure(REFERENCE, 100.0, "ms", true),
            figure("a", 10.0, "ms", true),
            figure("b", 10.0, "ms", true),
            figure("wall", 1.0, "s", false),
        ];
        // The whole machine is twice as slow: a is unchanged relative to the reference,
        // b is 25 % worse, the wall figure is 10x worse but not compared.
        let now = vec![
            figure(REFERENCE, 200.0, "ms", true),
            figure("a", 20.0, "ms", true),
            figure("b", 25.0, "ms", true),
            figure("wall", 10.0, "s", false),
            figure("new", 1.0, "ms", true),
        ];
        let c = compare(&base, &now, REFERENCE, TOLERANCE).unwrap();
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].name, "a");
        assert!(!c[0].regressed);
        assert!((c[0].ratio - 1.0).abs() < 1e-12);
        assert_eq!(c[1].name, "b");
        assert!(c[1].regressed);
        assert!((c[1].ratio - 1.25).abs() < 1e-12);
        // 19 % worse passes.
        let now19 = vec![
            figure(REFERENCE, 100.0, "ms", true),
            figure("b", 11.9, "ms", true),
        ];
        assert!(!compare(&base, &now19, REFERENCE, TOLERANCE).unwrap()[0].regressed);
        assert!(compare(&base, &now[1..], REFERENCE, TOLERANCE).is_err());
        let err = check(&c, "benchmarks/baseline.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("b (+25 %)"), "{err}");
        assert!(!err.contains("a ("), "{err}");
        assert!(
            err.contains("slower than benchmarks/baseline.json"),
            "{err}"
        );
        assert!(check(&c[..1], "benchmarks/baseline.json").is_ok());
        let md = markdown(
            &Report {
                note: None,
                machine: Machine::default(),
                commit: "abc".into(),
                command: "cargo xtask bench".into(),
                reference: REFERENCE.into(),
                figures: now.clone(),
            },
            &c,
            "benchmarks/baseline.json",
        );
        assert!(md.contains("| b | 25.00 | ms | 0.1250 | +25.0 % REGRESSED |"));
        assert_eq!(significant(0.000707), "0.0007070");
        assert_eq!(significant(291.66667), "291.7");
    }

    #[test]
    fn each_cpu_model_has_its_own_baseline() {
        assert_eq!(
            slug("Intel(R) Xeon(R) Processor"),
            "intel-r-xeon-r-processor"
        );
        assert_eq!(
            slug("  AMD EPYC 7763 64-Core Processor "),
            "amd-epyc-7763-64-core-processor"
        );
        assert_eq!(slug("()"), "unknown-cpu");
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        std::fs::create_dir(root.join("benchmarks")).unwrap();
        let main = root.join("benchmarks/baseline.json");
        let intel = root.join("benchmarks/baseline-intel-r-xeon-r-processor.json");
        // No baseline yet: the first one is the main one.
        assert_eq!(
            baseline_for(root, "Intel(R) Xeon(R) Processor", true).unwrap(),
            main
        );
        let mut base = Report {
            note: None,
            machine: Machine::default(),
            commit: "abc".into(),
            command: "cargo xtask bench".into(),
            reference: REFERENCE.into(),
            figures: Vec::new(),
        };
        base.machine.model = "AMD EPYC 7763 64-Core Processor".into();
        write_json(&main, &base).unwrap();
        // The main baseline's model, spaced otherwise: the main one.
        let epyc = " AMD EPYC 7763  64-Core Processor";
        assert_eq!(baseline_for(root, epyc, true).unwrap(), main);
        assert_eq!(baseline_for(root, epyc, false).unwrap(), main);
        // A name that only begins like it is another CPU's (another EPYC generation): its
        // own file, the main one compared until it has one.
        let other = "AMD EPYC 9654 96-Core Processor";
        let own = root.join("benchmarks/baseline-amd-epyc-9654-96-core-processor.json");
        assert_eq!(baseline_for(root, other, true).unwrap(), own);
        assert_eq!(baseline_for(root, other, false).unwrap(), main);
        base.machine.model = "AMD EPYC".into();
        write_json(&main, &base).unwrap();
        assert_eq!(
            baseline_for(root, epyc, true).unwrap(),
            root.join("benchmarks/baseline-amd-epyc-7763-64-core-processor.json")
        );
        // Another model: recorded into its own; compared with the main one until it has one.
        let xeon = "Intel(R) Xeon(R) Processor";
        assert_eq!(baseline_for(root, xeon, true).unwrap(), intel);
        assert_eq!(baseline_for(root, xeon, false).unwrap(), main);
        write_json(&intel, &base).unwrap();
        assert_eq!(baseline_for(root, xeon, false).unwrap(), intel);
        assert_eq!(baseline_for(root, xeon, true).unwrap(), intel);
        // A main baseline without a model is no CPU's: never recorded over, not even by a
        // machine that names none either.
        for nameless in ["", " - "] {
            base.machine.model = nameless.into();
            write_json(&main, &base).unwrap();
            assert_eq!(
                baseline_for(root, epyc, true).unwrap(),
                root.join("benchmarks/baseline-amd-epyc-7763-64-core-processor.json")
            );
            assert_eq!(
                baseline_for(root, "", true).unwrap(),
                root.join("benchmarks/baseline-unknown-cpu.json")
            );
        }
        // One that cannot be read is an error, not an absent one to write.
        std::fs::remove_file(&main).unwrap();
        std::fs::create_dir(&main).unwrap();
        assert!(baseline_for(root, epyc, true).is_err());
    }
}
