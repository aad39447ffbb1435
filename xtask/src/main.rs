use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};

use xtask::checksum;
use xtask::fetch::{self, Outcome};
use xtask::manifest::Manifest;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    bin_name = "cargo xtask",
    about = "Developer tasks for ridi-rs"
)]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Download a dataset of datasets/manifest.toml (or install it from a local copy), verify
    /// it and unpack it into <dir>/<dataset>.
    Fetch {
        /// Dataset name in the manifest (e.g. ridi, tyrex).
        dataset: String,
        /// Local archive (checked against the pinned sha256) or folder (checked against the
        /// dataset's per-file list) to use instead of downloading.
        #[arg(long, value_name = "PATH")]
        from: Option<PathBuf>,
        /// Folder holding the datasets [default: <workspace>/datasets].
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
        /// Manifest to read [default: <workspace>/datasets/manifest.toml].
        #[arg(long, value_name = "FILE")]
        manifest: Option<PathBuf>,
        /// Accept content that no checksum in the repository vouches for, and print its
        /// sha256 so that it can be pinned.
        #[arg(long)]
        trust_unpinned: bool,
    },
    /// Print the sha256sum list of every file under a folder (sorted), e.g. to regenerate
    /// datasets/<name>.sha256.
    Checksums { folder: PathBuf },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.task {
        Task::Fetch {
            dataset,
            from,
            dir,
            manifest,
            trust_unpinned,
        } => {
            let root = xtask::workspace_root();
            let manifest_path = manifest.unwrap_or_else(|| root.join("datasets/manifest.toml"));
            let manifest = Manifest::load(&manifest_path)?;
            let ds = manifest.get(&dataset)?;
            let opts = fetch::Options {
                dir: dir.unwrap_or_else(|| root.join("datasets")),
                from,
                trust_unpinned,
                progress: true,
            };
            match fetch::fetch(ds, &opts)? {
                Outcome::AlreadyPresent { path, source } => {
                    println!("{dataset}: already in {} (from {source})", path.display());
                }
                Outcome::Installed {
                    path,
                    archive_sha256,
                    verified,
                    files,
                } => {
                    println!("{dataset}: {files} files in {}", path.display());
                    if !verified {
                        match archive_sha256 {
                            Some(sha) => println!(
                                "{dataset}: UNPINNED archive, sha256 {sha}; to pin it set \
                                 sha256 = \"{sha}\" in {}",
                                manifest.path.display()
                            ),
                            None => println!(
                                "{dataset}: UNVERIFIED copy; to pin it commit the output of \
                                 `cargo xtask checksums {}` as a per-file list",
                                path.display()
                            ),
                        }
                    }
                }
            }
        }
        Task::Checksums { folder } => {
            let list = checksum::list_tree(&folder)?;
            print!("{}", checksum::format_list(&list));
        }
    }
    Ok(())
}
