//! `fetch` against an HTTP server on 127.0.0.1 started by each test, serving fixture
//! archives built by the test.

use std::fs;
use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use ridi_test_support::{file_names, shared_dataset};
use xtask::checksum::{self, ListEntry};
use xtask::fetch::{self, MARKER, Marker, Options, Outcome};
use xtask::manifest::Dataset;

// ---------------------------------------------------------------------------------------
// Test server: one thread, one connection at a time, closes every connection after the
// reply, and stops when dropped or after a time limit and a request count, whichever first.

#[derive(Clone, Debug)]
struct Seen {
    path: String,
    range: Option<u64>,
}

struct Reply {
    status: u16,
    headers: Vec<(String, String)>,
    body: Vec<u8>,
    /// Content-Length announced; larger than `body` simulates a connection that dies.
    declared_len: usize,
}

impl Reply {
    fn status(status: u16) -> Self {
        Reply {
            status,
            headers: vec![],
            body: b"oops".to_vec(),
            declared_len: 4,
        }
    }

    /// The resource `data`, honouring `Range: bytes=N-` when `ranges` is set.
    fn file(data: &[u8], range: Option<u64>, ranges: bool) -> Self {
        match range {
            Some(start) if ranges && (start as usize) < data.len() => {
                let body = data[start as usize..].to_vec();
                let cr = format!("bytes {start}-{}/{}", data.len() - 1, data.len());
                Reply {
                    status: 206,
                    headers: vec![("Content-Range".into(), cr)],
                    declared_len: body.len(),
                    body,
                }
            }
            Some(_) if ranges => Reply {
                status: 416,
                headers: vec![("Content-Range".into(), format!("bytes */{}", data.len()))],
                body: vec![],
                declared_len: 0,
            },
            _ => Reply {
                status: 200,
                headers: vec![],
                body: data.to_vec(),
                declared_len: data.len(),
            },
        }
    }
}

type Handler = dyn Fn(usize, &Seen) -> Reply + Send + Sync;

struct Server {
    base: String,
    seen: Arc<Mutex<Vec<Seen>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

const MAX_REQUESTS: usize = 32;
const LIFETIME: Duration = Duration::from_secs(30);

impl Server {
    fn start(handler: impl Fn(usize, &Seen) -> Reply + Send + Sync + 'static) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        listener.set_nonblocking(true).unwrap();
        let base = format!("http://{}", listener.local_addr().unwrap());
        let seen = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let handler: Box<Handler> = Box::new(handler);
        let thread = {
            let (seen, stop) = (seen.clone(), stop.clone());
            std::thread::spawn(move || {
                let deadline = Instant::now() + LIFETIME;
                let mut count = 0;
                while !stop.load(Ordering::Relaxed)
                    && Instant::now() < deadline
                    && count < MAX_REQUESTS
                {
                    match listener.accept() {
                        Ok((stream, _)) => {
                            if let Some(req) = read_request(&stream) {
                                let reply = handler(count, &req);
                                seen.lock().unwrap().push(req);
                                write_reply(stream, reply);
                            }
                            count += 1;
                        }
                        Err(_) => std::thread::sleep(Duration::from_millis(5)),
                    }
                }
            })
        };
        Server {
            base,
            seen,
            stop,
            thread: Some(thread),
        }
    }

    fn url(&self, path: &str) -> String {
        format!("{}{path}", self.base)
    }

    fn requests(&self) -> Vec<Seen> {
        self.seen.lock().unwrap().clone()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn read_request(stream: &TcpStream) -> Option<Seen> {
    stream.set_nonblocking(false).ok()?;
    stream.set_read_timeout(Some(Duration::from_secs(5))).ok()?;
    let mut reader = BufReader::new(stream);
    let mut line = String::new();
    reader.read_line(&mut line).ok()?;
    let path = line.split_whitespace().nth(1)?.to_owned();
    let mut range = None;
    loop {
        let mut h = String::new();
        if reader.read_line(&mut h).ok()? == 0 || h == "\r\n" {
            break;
        }
        let (name, value) = h.split_once(':')?;
        if name.eq_ignore_ascii_case("range") {
            let v = value.trim().strip_prefix("bytes=")?.strip_suffix('-')?;
            range = v.parse().ok();
        }
    }
    Some(Seen { path, range })
}

fn write_reply(mut stream: TcpStream, reply: Reply) {
    let mut head = format!(
        "HTTP/1.1 {} X\r\nContent-Length: {}\r\nConnection: close\r\n",
        reply.status, reply.declared_len
    );
    for (k, v) in &reply.headers {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    head.push_str("\r\n");
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(&reply.body);
    let _ = stream.flush();
    // Dropping the stream closes it: a short body then reads as a broken transfer.
}

// ---------------------------------------------------------------------------------------
// Fixtures.

const FILES: &[(&str, &str)] = &[
    ("seq1/data.csv", "time,x\n0,1\n"),
    ("seq2/data.csv", "time,x\n0,2\n"),
    ("list.txt", "seq1\nseq2\n"),
];

fn tar_gz(entries: &[(&str, &[u8])]) -> Vec<u8> {
    let enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    let mut b = tar::Builder::new(enc);
    for (name, data) in entries {
        let mut h = tar::Header::new_gnu();
        h.set_size(data.len() as u64);
        h.set_mode(0o644);
        h.set_entry_type(tar::EntryType::Regular);
        // Written into the raw name field: `set_path` refuses `..`, and the malicious
        // fixtures need exactly that.
        let field = &mut h.as_old_mut().name;
        field[..name.len()].copy_from_slice(name.as_bytes());
        h.set_cksum();
        b.append(&h, *data).unwrap();
    }
    b.into_inner().unwrap().finish().unwrap()
}

/// A good archive: a top folder `top/` holding FILES, padded with incompressible bytes so
/// that a truncated transfer has something to cut.
fn good_archive() -> Vec<u8> {
    let mut noise = vec![0u8; 200_000];
    let mut x: u32 = 12345;
    for b in &mut noise {
        x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
        *b = (x >> 24) as u8;
    }
    let mut entries: Vec<(String, Vec<u8>)> = FILES
        .iter()
        .map(|(n, c)| (format!("top/{n}"), c.as_bytes().to_vec()))
        .collect();
    entries.push(("top/noise.bin".into(), noise));
    let refs: Vec<(&str, &[u8])> = entries
        .iter()
        .map(|(n, d)| (n.as_str(), d.as_slice()))
        .collect();
    tar_gz(&refs)
}

fn sha(bytes: &[u8]) -> String {
    checksum::sha256_reader(bytes).unwrap()
}

fn dataset(urls: Vec<String>, sha256: &str) -> Dataset {
    Dataset {
        name: "demo".into(),
        description: "test fixture".into(),
        licence: "test".into(),
        homepage: None,
        urls,
        sha256: sha256.into(),
        size: None,
        strip_prefix: Some("top".into()),
        layout: vec!["list.txt".into(), "seq1/data.csv".into()],
        files: None,
    }
}

fn options(dir: &Path) -> Options {
    Options {
        dir: dir.to_path_buf(),
        from: None,
        trust_unpinned: false,
        progress: false,
    }
}

fn assert_installed(dir: &Path) {
    let root = dir.join("demo");
    for (name, content) in FILES {
        assert_eq!(
            fs::read_to_string(root.join(name)).unwrap(),
            *content,
            "{name}"
        );
    }
    assert!(root.join(MARKER).is_file());
    // Nothing but the dataset: no .part, no staging folder.
    assert_eq!(file_names(dir), vec!["demo".to_string()]);
}

fn err_text(r: anyhow::Result<Outcome>) -> String {
    format!("{:#}", r.expect_err("fetch should fail"))
}

// ---------------------------------------------------------------------------------------

#[test]
fn good_archive_is_downloaded_verified_and_installed() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(&archive));
    let out = fetch::fetch(&ds, &options(tmp.path())).unwrap();
    match out {
        Outcome::Installed {
            archive_sha256,
            verified,
            files,
            ..
        } => {
            assert_eq!(archive_sha256.as_deref(), Some(sha(&archive).as_str()));
            assert!(verified);
            assert_eq!(files, FILES.len() + 1);
        }
        other => panic!("{other:?}"),
    }
    assert_installed(tmp.path());
    let marker: Marker =
        toml::from_str(&fs::read_to_string(tmp.path().join("demo").join(MARKER)).unwrap()).unwrap();
    assert_eq!(marker.archive_sha256, Some(sha(&archive)));
}

#[test]
fn leftovers_of_a_killed_fetch_are_cleaned_up() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let tmp = tempfile::tempdir().unwrap();
    let stale = tmp.path().join(".demo.staging-abc123");
    fs::create_dir_all(stale.join("seq1")).unwrap();
    fs::write(stale.join("seq1/data.csv"), "half").unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(&archive));
    fetch::fetch(&ds, &options(tmp.path())).unwrap();
    assert_installed(tmp.path());
}

#[test]
fn second_run_is_a_no_op_without_any_request() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(&archive));
    fetch::fetch(&ds, &options(tmp.path())).unwrap();
    assert_eq!(server.requests().len(), 1);
    let again = fetch::fetch(&ds, &options(tmp.path())).unwrap();
    assert!(matches!(again, Outcome::AlreadyPresent { .. }), "{again:?}");
    assert_eq!(
        server.requests().len(),
        1,
        "the second run contacted the server"
    );
}

#[test]
fn a_changed_pin_replaces_the_stale_dataset() {
    let old = good_archive();
    let new = tar_gz(&[
        ("top/list.txt", b"seq1\n"),
        ("top/seq1/data.csv", b"time,x\n0,9\n"),
    ]);
    let (o, n) = (old.clone(), new.clone());
    let server = Server::start(move |_, req| {
        Reply::file(if req.path == "/old" { &o } else { &n }, req.range, true)
    });
    let tmp = tempfile::tempdir().unwrap();
    fetch::fetch(
        &dataset(vec![server.url("/old")], &sha(&old)),
        &options(tmp.path()),
    )
    .unwrap();
    fetch::fetch(
        &dataset(vec![server.url("/new")], &sha(&new)),
        &options(tmp.path()),
    )
    .unwrap();
    let root = tmp.path().join("demo");
    assert_eq!(
        fs::read_to_string(root.join("seq1/data.csv")).unwrap(),
        "time,x\n0,9\n"
    );
    assert!(
        !root.join("seq2").exists(),
        "content of the old archive survived"
    );
    assert_eq!(file_names(tmp.path()), vec!["demo".to_string()]);
}

#[test]
fn wrong_checksum_is_rejected_and_nothing_is_left() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(b"something else"));
    let err = err_text(fetch::fetch(&ds, &options(tmp.path())));
    assert!(err.contains("sha256 mismatch"), "{err}");
    assert!(
        file_names(tmp.path()).is_empty(),
        "left behind: {:?}",
        file_names(tmp.path())
    );
}

#[test]
fn truncated_transfer_fails_then_resumes_with_a_range_request() {
    let archive = good_archive();
    let cut = archive.len() / 3;
    let served = archive.clone();
    let server = Server::start(move |n, req| {
        if n == 0 {
            // Announce everything, send a third, hang up.
            Reply {
                status: 200,
                headers: vec![],
                body: served[..cut].to_vec(),
                declared_len: served.len(),
            }
        } else {
            Reply::file(&served, req.range, true)
        }
    });
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(&archive));
    let err = err_text(fetch::fetch(&ds, &options(tmp.path())));
    assert!(err.contains("run again to resume"), "{err}");
    assert!(!tmp.path().join("demo").exists());
    let part = tmp.path().join(".demo.part");
    assert_eq!(fs::metadata(&part).unwrap().len(), cut as u64);

    fetch::fetch(&ds, &options(tmp.path())).unwrap();
    let reqs = server.requests();
    assert_eq!(reqs.len(), 2);
    assert_eq!(reqs[0].range, None);
    assert_eq!(reqs[1].range, Some(cut as u64), "second run did not resume");
    assert_installed(tmp.path());
}

#[test]
fn truncated_transfer_restarts_cleanly_when_the_server_ignores_ranges() {
    let archive = good_archive();
    let cut = archive.len() / 2;
    let served = archive.clone();
    let server = Server::start(move |n, req| {
        if n == 0 {
            Reply {
                status: 200,
                headers: vec![],
                body: served[..cut].to_vec(),
                declared_len: served.len(),
            }
        } else {
            Reply::file(&served, req.range, false)
        }
    });
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(&archive));
    assert!(fetch::fetch(&ds, &options(tmp.path())).is_err());
    fetch::fetch(&ds, &options(tmp.path())).unwrap();
    assert_eq!(server.requests()[1].range, Some(cut as u64));
    // The 200 reply replaced the partial bytes instead of being appended to them.
    assert_installed(tmp.path());
}

#[test]
fn server_error_fails_with_the_status_and_leaves_nothing() {
    let server = Server::start(|_, _| Reply::status(500));
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], &sha(b"x"));
    let err = err_text(fetch::fetch(&ds, &options(tmp.path())));
    assert!(err.contains("HTTP 500"), "{err}");
    assert!(!err.contains('\n'), "error is not one line: {err}");
    assert!(
        file_names(tmp.path()).is_empty(),
        "left behind: {:?}",
        file_names(tmp.path())
    );
}

#[test]
fn a_failing_mirror_falls_through_to_the_next() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| {
        if req.path == "/dead" {
            Reply::status(404)
        } else {
            Reply::file(&served, req.range, true)
        }
    });
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(
        vec![server.url("/dead"), server.url("/alive")],
        &sha(&archive),
    );
    fetch::fetch(&ds, &options(tmp.path())).unwrap();
    let paths: Vec<String> = server.requests().into_iter().map(|r| r.path).collect();
    assert_eq!(paths, ["/dead", "/alive"]);
    assert_installed(tmp.path());
}

#[test]
fn archive_with_parent_dir_entries_is_rejected() {
    let evil = tar_gz(&[
        ("top/list.txt", b"seq1\n"),
        ("top/../../escaped.txt", b"pwned"),
    ]);
    let served = evil.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let outer = tempfile::tempdir().unwrap();
    let dir = outer.path().join("a").join("datasets");
    let ds = dataset(vec![server.url("/evil.tar.gz")], &sha(&evil));
    let err = err_text(fetch::fetch(&ds, &options(&dir)));
    assert!(err.contains("unsafe path"), "{err}");
    for p in [
        outer.path().join("escaped.txt"),
        outer.path().join("a/escaped.txt"),
        dir.join("escaped.txt"),
    ] {
        assert!(!p.exists(), "{} was written", p.display());
    }
    assert!(
        file_names(&dir).is_empty(),
        "left behind: {:?}",
        file_names(&dir)
    );
}

#[test]
fn unpinned_archive_is_refused_before_any_request_unless_trusted() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let tmp = tempfile::tempdir().unwrap();
    let ds = dataset(vec![server.url("/a.tar.gz")], "");
    let err = err_text(fetch::fetch(&ds, &options(tmp.path())));
    assert!(err.contains("--trust-unpinned"), "{err}");
    assert!(server.requests().is_empty());

    let trusted = Options {
        trust_unpinned: true,
        ..options(tmp.path())
    };
    match fetch::fetch(&ds, &trusted).unwrap() {
        Outcome::Installed {
            archive_sha256,
            verified,
            ..
        } => {
            assert_eq!(archive_sha256, Some(sha(&archive)), "the sha256 to pin");
            assert!(!verified);
        }
        other => panic!("{other:?}"),
    }
    assert_installed(tmp.path());
}

#[test]
fn missing_layout_path_is_reported_and_nothing_installed() {
    let archive = good_archive();
    let served = archive.clone();
    let server = Server::start(move |_, req| Reply::file(&served, req.range, true));
    let tmp = tempfile::tempdir().unwrap();
    let mut ds = dataset(vec![server.url("/a.tar.gz")], &sha(&archive));
    ds.layout.push("seq3/data.csv".into());
    let err = err_text(fetch::fetch(&ds, &options(tmp.path())));
    assert!(err.contains("seq3/data.csv"), "{err}");
    assert!(
        file_names(tmp.path()).is_empty(),
        "left behind: {:?}",
        file_names(tmp.path())
    );
}

#[test]
fn from_local_archive_zip_is_verified_and_unpacked() {
    let tmp = tempfile::tempdir().unwrap();
    let zip_path = tmp.path().join("copy.zip");
    {
        let mut w = zip::ZipWriter::new(fs::File::create(&zip_path).unwrap());
        let opts = zip::write::SimpleFileOptions::default();
        for (name, content) in FILES {
            w.start_file(format!("top/{name}"), opts).unwrap();
            w.write_all(content.as_bytes()).unwrap();
        }
        w.finish().unwrap();
    }
    let bytes = fs::read(&zip_path).unwrap();
    let dir = tmp.path().join("datasets");
    let from = Options {
        from: Some(zip_path.clone()),
        ..options(&dir)
    };

    let wrong = dataset(vec![], &sha(b"other"));
    let err = err_text(fetch::fetch(&wrong, &from));
    assert!(err.contains("sha256 mismatch"), "{err}");

    fetch::fetch(&dataset(vec![], &sha(&bytes)), &from).unwrap();
    let root = dir.join("demo");
    for (name, content) in FILES {
        assert_eq!(fs::read_to_string(root.join(name)).unwrap(), *content);
    }
    assert!(zip_path.is_file(), "the user's archive must be kept");
}

fn write_tree(root: &Path) {
    for (name, content) in FILES {
        let p = root.join(name);
        fs::create_dir_all(p.parent().unwrap()).unwrap();
        fs::write(p, content).unwrap();
    }
}

fn list_for(root: &Path, at: &Path) -> PathBuf {
    let list = checksum::list_tree(root).unwrap();
    fs::write(at, checksum::format_list(&list)).unwrap();
    at.to_path_buf()
}

#[test]
fn from_local_folder_is_verified_file_by_file_and_copied() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("src");
    write_tree(&src);
    let mut ds = dataset(vec![], "");
    ds.files = Some(list_for(&src, &tmp.path().join("demo.sha256")));
    // A file outside the list is not part of the dataset.
    fs::write(src.join("notes.txt"), "scratch").unwrap();
    let dir = tmp.path().join("datasets");
    let opts = Options {
        from: Some(src.clone()),
        ..options(&dir)
    };

    match fetch::fetch(&ds, &opts).unwrap() {
        Outcome::Installed {
            verified, files, ..
        } => assert!(verified && files == FILES.len()),
        other => panic!("{other:?}"),
    }
    let root = dir.join("demo");
    for (name, content) in FILES {
        assert_eq!(fs::read_to_string(root.join(name)).unwrap(), *content);
        assert!(
            !fs::symlink_metadata(root.join(name))
                .unwrap()
                .file_type()
                .is_symlink()
        );
    }
    assert!(!root.join("notes.txt").exists());
    assert!(matches!(
        fetch::fetch(&ds, &opts).unwrap(),
        Outcome::AlreadyPresent { .. }
    ));
}

#[test]
fn from_local_folder_with_a_modified_file_is_rejected() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("src");
    write_tree(&src);
    let mut ds = dataset(vec![], "");
    ds.files = Some(list_for(&src, &tmp.path().join("demo.sha256")));
    fs::write(src.join("seq2/data.csv"), "time,x\n0,3\n").unwrap();
    fs::remove_file(src.join("list.txt")).unwrap();
    let dir = tmp.path().join("datasets");
    let err = err_text(fetch::fetch(
        &ds,
        &Options {
            from: Some(src),
            ..options(&dir)
        },
    ));
    assert!(err.contains("2 of 3 files"), "{err}");
    assert!(err.contains("list.txt: missing"), "{err}");
    assert!(
        file_names(&dir).is_empty(),
        "left behind: {:?}",
        file_names(&dir)
    );
}

#[test]
fn from_local_folder_may_be_the_parent_of_the_archive_top_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("Downloads");
    write_tree(&src.join("top"));
    let mut ds = dataset(vec![], "");
    ds.files = Some(list_for(&src.join("top"), &tmp.path().join("demo.sha256")));
    let dir = tmp.path().join("datasets");
    fetch::fetch(
        &ds,
        &Options {
            from: Some(src),
            ..options(&dir)
        },
    )
    .unwrap();
    assert_eq!(
        fs::read_to_string(dir.join("demo/list.txt")).unwrap(),
        "seq1\nseq2\n"
    );
}

#[test]
fn from_local_folder_without_a_list_needs_trust() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("src");
    write_tree(&src);
    let ds = dataset(vec![], "");
    let dir = tmp.path().join("datasets");
    let opts = Options {
        from: Some(src),
        ..options(&dir)
    };
    assert!(err_text(fetch::fetch(&ds, &opts)).contains("--trust-unpinned"));
    let trusted = Options {
        trust_unpinned: true,
        ..opts
    };
    match fetch::fetch(&ds, &trusted).unwrap() {
        Outcome::Installed {
            verified, files, ..
        } => assert!(!verified && files == FILES.len()),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_folder_not_made_by_fetch_is_never_overwritten() {
    let tmp = tempfile::tempdir().unwrap();
    let mine = tmp.path().join("demo");
    fs::create_dir_all(&mine).unwrap();
    fs::write(mine.join("precious.txt"), "keep").unwrap();
    let ds = dataset(vec!["http://127.0.0.1:9/unused".into()], &sha(b"x"));
    let err = err_text(fetch::fetch(&ds, &options(tmp.path())));
    assert!(err.contains("not made by `cargo xtask fetch`"), "{err}");
    assert_eq!(
        fs::read_to_string(mine.join("precious.txt")).unwrap(),
        "keep"
    );
}

/// The committed per-file lists describe the project's local copies exactly.
#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn committed_lists_match_the_shared_local_copies() {
    let root = xtask::workspace_root();
    for (list, folder, probe) in [
        (
            "tyrex.sha256",
            "tyrex-attitude-smartphones",
            "datasets/android",
        ),
        (
            "indoor-location-competition-20.sha256",
            "indoor-location-competition-20",
            "data",
        ),
    ] {
        let folder = shared_dataset(folder, probe);
        let text = fs::read_to_string(root.join("datasets").join(list)).unwrap();
        let committed = checksum::parse_list(&text, Path::new(list)).unwrap();
        let actual: Vec<ListEntry> = checksum::list_tree(&folder).unwrap();
        assert_eq!(
            committed, actual,
            "{list} is out of date; regenerate with cargo xtask checksums"
        );
    }
}
