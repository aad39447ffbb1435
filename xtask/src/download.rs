//! Streaming an HTTP download into a `.part` file, resuming it with a Range request.

use std::fs::{self, File, OpenOptions};
use std::io::{IsTerminal, Read, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

pub fn agent() -> ureq::Agent {
    ureq::Agent::config_builder()
        // Statuses are handled here: 206 and 416 matter for resuming.
        .http_status_as_error(false)
        .timeout_connect(Some(Duration::from_secs(30)))
        .timeout_recv_response(Some(Duration::from_secs(120)))
        .user_agent(concat!("ridi-rs-xtask/", env!("CARGO_PKG_VERSION")))
        .build()
        .into()
}

/// What a `.part` file holds, kept beside it so a later run knows whether the bytes may be
/// continued: with a pinned sha256 any mirror may finish the file (the hash checks the
/// result), without one only the same URL may.
#[derive(Debug, Clone, PartialEq, Eq)]
struct PartSource {
    key: String,
    etag: Option<String>,
}

pub fn source_path(part: &Path) -> PathBuf {
    let mut name = part.as_os_str().to_owned();
    name.push(".source");
    PathBuf::from(name)
}

fn read_source(part: &Path) -> Option<PartSource> {
    let text = fs::read_to_string(source_path(part)).ok()?;
    let mut lines = text.lines();
    let key = lines.next()?.to_owned();
    let etag = lines.next().filter(|l| !l.is_empty()).map(str::to_owned);
    Some(PartSource { key, etag })
}

fn write_source(part: &Path, src: &PartSource) -> Result<()> {
    let path = source_path(part);
    let text = format!("{}\n{}\n", src.key, src.etag.as_deref().unwrap_or(""));
    fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// Removes a partial download and its source note.
pub fn discard(part: &Path) {
    let _ = fs::remove_file(part);
    let _ = fs::remove_file(source_path(part));
}

/// `Content-Range: bytes START-END/TOTAL` -> (START, TOTAL); TOTAL may be `*`.
fn parse_content_range(value: &str) -> Option<(u64, Option<u64>)> {
    let rest = value.trim().strip_prefix("bytes ")?;
    let (range, total) = rest.split_once('/')?;
    let (start, _end) = range.split_once('-')?;
    let total = if total == "*" {
        None
    } else {
        Some(total.parse().ok()?)
    };
    Some((start.parse().ok()?, total))
}

fn header<'a>(resp: &'a ureq::http::Response<ureq::Body>, name: &str) -> Option<&'a str> {
    resp.headers().get(name).and_then(|v| v.to_str().ok())
}

pub struct Request<'a> {
    pub url: &'a str,
    pub part: &'a Path,
    /// Identifies the content (see `PartSource`).
    pub key: String,
    pub expected_size: Option<u64>,
    pub progress: bool,
}

/// Leaves the complete response body in `req.part`. A failed transfer leaves the bytes
/// received so far, for the next run to resume.
pub fn download(agent: &ureq::Agent, req: &Request<'_>) -> Result<u64> {
    // Two rounds at most: the second one only after a 416 made us drop the partial file.
    for _ in 0..2 {
        if let Some(done) = attempt(agent, req)? {
            return Ok(done);
        }
    }
    bail!("{}: server keeps refusing the byte range", req.url)
}

fn attempt(agent: &ureq::Agent, req: &Request<'_>) -> Result<Option<u64>> {
    let url = req.url;
    let previous = read_source(req.part).filter(|s| s.key == req.key);
    let mut offset = match (&previous, fs::metadata(req.part)) {
        (Some(_), Ok(meta)) => meta.len(),
        _ => 0,
    };
    if let Some(size) = req.expected_size {
        if offset == size {
            return Ok(Some(size));
        }
        if offset > size {
            offset = 0;
        }
    }
    if offset == 0 {
        discard(req.part);
    }

    let mut get = agent.get(url);
    if offset > 0 {
        get = get.header("Range", format!("bytes={offset}-"));
        // With If-Range the server sends the whole new file (200) if it changed meanwhile.
        if let Some(etag) = previous.as_ref().and_then(|p| p.etag.as_deref()) {
            get = get.header("If-Range", etag);
        }
    }
    let resp = get.call().with_context(|| format!("GET {url} failed"))?;
    let status = resp.status().as_u16();
    let etag = header(&resp, "etag")
        .filter(|e| !e.starts_with("W/"))
        .map(str::to_owned);
    let (start, total) = match status {
        206 if offset > 0 => {
            let range = header(&resp, "content-range")
                .with_context(|| format!("{url}: 206 response without Content-Range"))?;
            let (start, total) = parse_content_range(range)
                .with_context(|| format!("{url}: bad Content-Range `{range}`"))?;
            if start != offset {
                bail!("{url}: asked to resume at byte {offset}, server sent from byte {start}");
            }
            let total = total.or_else(|| resp.body().content_length().map(|l| l + offset));
            (offset, total)
        }
        200 => (0, resp.body().content_length()),
        416 if offset > 0 => {
            eprintln!("  {url}: server refused to resume at byte {offset}; starting over");
            discard(req.part);
            return Ok(None);
        }
        _ => {
            let reason = resp.status().canonical_reason().unwrap_or("");
            bail!("HTTP {status} {reason} from {url}");
        }
    };
    if let (Some(total), Some(size)) = (total, req.expected_size)
        && total != size
    {
        discard(req.part);
        bail!("{url} serves {total} bytes, the manifest expects {size}");
    }

    let mut file = if start == 0 {
        if offset > 0 {
            eprintln!("  {url}: server does not resume downloads; starting over");
        }
        File::create(req.part)
    } else {
        eprintln!("  resuming at byte {start}");
        OpenOptions::new().append(true).open(req.part)
    }
    .with_context(|| format!("cannot write {}", req.part.display()))?;
    write_source(
        req.part,
        &PartSource {
            key: req.key.clone(),
            etag,
        },
    )?;

    let bar = progress_bar(total, start, req.progress);
    let mut body = resp.into_body().into_reader();
    let mut received = start;
    let mut buf = vec![0u8; 1 << 16];
    let outcome: Result<()> = loop {
        match body.read(&mut buf) {
            Ok(0) => break Ok(()),
            Ok(n) => {
                if let Err(e) = file.write_all(&buf[..n]) {
                    break Err(e).with_context(|| format!("cannot write {}", req.part.display()));
                }
                received += n as u64;
                bar.set_position(received);
            }
            Err(e) => {
                break Err(e).with_context(|| {
                    format!(
                        "transfer from {url} broke off after {received} bytes; run again to resume"
                    )
                });
            }
        }
    };
    bar.finish_and_clear();
    file.flush()
        .and_then(|()| file.sync_all())
        .with_context(|| format!("cannot write {}", req.part.display()))?;
    outcome?;
    if let Some(total) = total
        && received != total
    {
        bail!("transfer from {url} truncated at {received} of {total} bytes; run again to resume");
    }
    Ok(Some(received))
}

fn progress_bar(total: Option<u64>, start: u64, enabled: bool) -> ProgressBar {
    // Hidden unless stderr is a terminal: CI logs must not fill with redraws.
    let target = if enabled && std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = match total {
        Some(t) => ProgressBar::with_draw_target(Some(t), target).with_style(
            ProgressStyle::with_template(
                "  {bar:40} {bytes}/{total_bytes} {bytes_per_sec} eta {eta}",
            )
            .expect("static template"),
        ),
        None => ProgressBar::with_draw_target(None, target).with_style(
            ProgressStyle::with_template("  {spinner} {bytes} {bytes_per_sec}")
                .expect("static template"),
        ),
    };
    bar.set_position(start);
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn content_range_parsing() {
        assert_eq!(
            parse_content_range("bytes 100-199/200"),
            Some((100, Some(200)))
        );
        assert_eq!(parse_content_range("bytes 5-9/*"), Some((5, None)));
        assert_eq!(parse_content_range("bytes */200"), None);
        assert_eq!(parse_content_range("items 1-2/3"), None);
    }
}
