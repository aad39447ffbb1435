//! `cargo xtask sample`: the small real sample bundled in `datasets/sample`, cut from the Tyrex
//! smartphone benchmark and converted to the RIDI processed layout.
//!
//! Every person and motion of the Nexus 5 runs without magnetic disturbance, and a slice of the
//! iPhone 4S runs (`IPHONE_RUNS`: the held-out person's, so that the demo tracks a phone its
//! model never saw), `SECONDS` seconds each from the first part of the run long enough, else
//! its longest (skipping the part's first `SKIP_S` seconds, where the mocap and the walker
//! settle), written as gzip-compressed `data.csv.gz` with `f32` precision and its sidecar (the
//! device), to stay under 15 MB. List files: one per person, one per phone (`list_nexus5.txt`,
//! `list_iphone4s.txt`, as `ridi convert` names them), `list_all.txt`, and the demo split
//! `list_train.txt` (Guillaume, Jakob) / `list_test.txt` (Thibaud). Placements are the motion
//! names.

use std::path::Path;

use anyhow::{Context, Result, bail};
use ridi_data::tyrex::{self, TyrexOptions};
use ridi_data::{Precision, write_atomically, write_ridi_csv_with};

/// Seconds kept per run.
pub const SECONDS: f64 = 24.0;
/// Seconds skipped at the start of the chosen part.
pub const SKIP_S: f64 = 5.0;
/// People held out for the demo's test split.
pub const TEST_PEOPLE: [&str; 1] = ["Thibaud"];
/// The iPhone 4S runs kept: the held-out person's, one hand-held and one in a pocket (chosen
/// for being the two commonest ways to carry a phone, not for their figures); a third run would
/// leave under 0.2 MB of the 15 MB budget.
pub const IPHONE_RUNS: [&str; 2] = [
    "Thibaud_iPhone4S_NoDist_Texting",
    "Thibaud_iPhone4S_NoDist_FrontPocket",
];

/// One run of the sample, sorted by person then name.
#[derive(Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Entry {
    person: String,
    name: String,
    motion: String,
    /// `DeviceInfo::key` of its phone (`nexus5`, `iphone4s`).
    device: Option<String>,
}

/// Builds the sample from the Tyrex root `data` into `out` (replacing its sequence folders and
/// lists; other files such as the licence are left alone).
pub fn build(data: &Path, out: &Path) -> Result<()> {
    let runs = tyrex::list_sequences(data)?.runs;
    let mut lines: Vec<Entry> = Vec::new();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    for dir in runs {
        let name = dir
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        if !name.contains("_Nexus5_NoDist_") && !IPHONE_RUNS.contains(&name.as_str()) {
            continue;
        }
        let read = tyrex::read(&dir, &TyrexOptions::default())?;
        // The first part that holds the whole slice, else the longest: a cut later in the run
        // (a mocap loss, a flip the reader cuts out) leaves the slice where it was.
        let Some(part) = read
            .sequences
            .iter()
            .find(|s| s.duration() >= SKIP_S + SECONDS)
            .or_else(|| {
                read.sequences
                    .iter()
                    .max_by(|a, b| a.duration().total_cmp(&b.duration()))
            })
        else {
            bail!("{}: no usable part", dir.display());
        };
        let t0 = part.time()[0];
        let skip = if part.duration() >= SKIP_S + SECONDS {
            SKIP_S
        } else {
            0.0
        };
        let first = part.time().partition_point(|&t| t < t0 + skip);
        let last = part.time().partition_point(|&t| t < t0 + skip + SECONDS);
        if last <= first + 1 {
            bail!("{}: part too short", dir.display());
        }
        if let Some(why) = ridi_data::unlistable_name(&name) {
            bail!(
                "{}: the run name cannot be a list line ({why})",
                dir.display()
            );
        }
        let mut seq = part.slice(first..last);
        seq.set_name(name.clone());
        let folder = out.join(&name).join("processed");
        std::fs::create_dir_all(&folder)?;
        write_ridi_csv_with(&seq, folder.join("data.csv.gz"), Precision::F32)?;
        let person = name.split('_').next().unwrap_or_default().to_string();
        let motion = seq.placement().unwrap_or_default().to_string();
        println!(
            "{name}: {:.1} s from {:.1} s, {} frames",
            seq.duration(),
            skip,
            seq.len()
        );
        lines.push(Entry {
            person,
            name,
            motion,
            device: seq.device().map(|d| d.key()),
        });
    }
    // A copy without one of the named iPhone runs would give a sample its lists and docs do
    // not describe.
    for run in IPHONE_RUNS {
        if !lines.iter().any(|l| l.name == run) {
            bail!("{}: no run {run} with motion capture", data.display());
        }
    }
    lines.sort();
    let people: std::collections::BTreeSet<&str> =
        lines.iter().map(|l| l.person.as_str()).collect();
    let mut lists: Vec<(String, Vec<&Entry>)> = vec![
        ("all".into(), lines.iter().collect()),
        (
            "train".into(),
            lines
                .iter()
                .filter(|l| !TEST_PEOPLE.contains(&l.person.as_str()))
                .collect(),
        ),
        (
            "test".into(),
            lines
                .iter()
                .filter(|l| TEST_PEOPLE.contains(&l.person.as_str()))
                .collect(),
        ),
    ];
    for p in people {
        lists.push((
            p.to_string(),
            lines.iter().filter(|l| l.person == p).collect(),
        ));
    }
    // One list per phone, named as `ridi convert` names them.
    let devices: std::collections::BTreeSet<&str> =
        lines.iter().filter_map(|l| l.device.as_deref()).collect();
    for d in devices {
        lists.push((
            d.to_string(),
            lines
                .iter()
                .filter(|l| l.device.as_deref() == Some(d))
                .collect(),
        ));
    }
    for (key, entries) in lists {
        let path = out.join(format!("list_{key}.txt"));
        write_atomically(&path, |w| {
            writeln!(w, "# written by `cargo xtask sample`: path,placement")?;
            for e in entries {
                writeln!(w, "{},{}", e.name, e.motion)?;
            }
            Ok(())
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// The every-phone issue's budget for the bundled sample, licence and lists included.
    const MAX_BYTES: u64 = 15_000_000;

    fn bytes_under(dir: &std::path::Path) -> u64 {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                let meta = e.metadata().unwrap();
                if meta.is_dir() {
                    bytes_under(&e.path())
                } else {
                    meta.len()
                }
            })
            .sum()
    }

    #[test]
    fn the_bundled_sample_stays_within_its_budget() {
        let bytes = bytes_under(&xtask::workspace_root().join("datasets/sample"));
        assert!(bytes <= MAX_BYTES, "datasets/sample holds {bytes} bytes");
    }
}
