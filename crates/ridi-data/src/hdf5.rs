//! A reader for the subset of HDF5 that h5py writes by default, enough for the RoNIN dataset's
//! `data.hdf5`: floating-point datasets in nested groups.
//!
//! # Why a reader of our own
//! The HDF5 bindings (`hdf5`, `hdf5-metno`) need the C library libhdf5 on every machine that
//! builds ridi-rs, and the workspace must build and test on a fresh machine with only a Rust
//! toolchain. The pure-Rust readers on crates.io (`hdf5-reader`, `hdf5-pure`, `rustyhdf5`,
//! `hdf5-rust`) were young and fast-moving when this was written, map files into memory
//! (undefined behaviour when a file shrinks under the map) or pull in `ndarray`, `rayon`, caches
//! and compression codecs, and none states that corrupt input never panics. RoNIN's files use a
//! small, stable part of the format (its `compile_dataset_h5.py` calls `create_dataset` with
//! h5py's defaults: contiguous, unfiltered `float64` arrays), which this module covers with no
//! dependency and checks every offset and length it reads, as the MAT reader (`mat.rs`) does
//! for MATLAB files.
//!
//! # What is supported
//! - Superblock versions 0 and 1 (h5py's default, `libver="earliest"`) and 2 and 3
//!   (`libver="latest"`), 2-, 4- or 8-byte offsets and lengths, at byte 0 or after a user block
//!   (512, 1024, ... bytes).
//! - Object headers version 1 and 2 with their continuation blocks (checksums are not verified).
//! - Groups as symbol tables (version 1 B-tree, symbol table nodes, local heap) or as compact
//!   link messages; hard links only. Dense link storage (fractal heap, a group of more than 8
//!   links under `libver="latest"`) is refused with an error.
//! - Datasets with a simple or scalar dataspace, an IEEE floating-point type of 4 or 8 bytes in
//!   either byte order, stored contiguously or compactly. Chunked (and so compressed) storage,
//!   external files, integer and other types are refused with an error naming the dataset.
//!
//! # Robustness
//! Every address and length read from the file is checked against the file size before it is
//! used; B-tree descent and continuation chains are bounded in depth and count, so a corrupt or
//! cyclic file ends in an error, never in a panic, an endless loop or a huge allocation.
//!
//! Internal to the crate (the RoNIN reader's): its items are `pub` only so that the `internals`
//! feature can hand them to the fuzz targets; not a supported API.

#![cfg_attr(not(feature = "internals"), allow(unreachable_pub, dead_code))]

use std::path::{Path, PathBuf};

use crate::error::{DataError, Location, Result};

const SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";
/// Deepest B-tree accepted (a real one of millions of links is a handful of levels deep).
const MAX_BTREE_DEPTH: usize = 32;
/// Most B-tree nodes, symbol-table nodes and symbol entries visited looking up one name:
/// bounds the work on a cyclic file (RoNIN's groups hold a few dozen links).
const MAX_NODES: usize = 1_000_000;
/// Most header blocks (the first and its continuations) of one object, and most messages.
const MAX_BLOCKS: usize = 1024;
const MAX_MESSAGES: usize = 65_536;
/// Deepest group nesting of a dataset path.
const MAX_PATH_DEPTH: usize = 32;

const MSG_DATASPACE: u16 = 0x0001;
const MSG_LINK_INFO: u16 = 0x0002;
const MSG_DATATYPE: u16 = 0x0003;
const MSG_LINK: u16 = 0x0006;
const MSG_LAYOUT: u16 = 0x0008;
const MSG_FILTERS: u16 = 0x000B;
const MSG_CONTINUATION: u16 = 0x0010;
const MSG_SYMBOL_TABLE: u16 = 0x0011;

/// An n-dimensional array of a dataset, row-major (C order, as numpy's default).
#[derive(Debug, Clone, PartialEq)]
pub struct Hdf5Array {
    /// The dimensions; empty for a scalar.
    pub shape: Vec<usize>,
    /// The values, `shape`'s product of them.
    pub data: Vec<f64>,
}

/// An HDF5 file held in memory.
#[derive(Debug, Clone)]
pub struct Hdf5File {
    bytes: Vec<u8>,
    path: PathBuf,
    /// Byte offset of the superblock: addresses are relative to it.
    base: usize,
    offset_size: usize,
    length_size: usize,
    /// Object header address of the root group.
    root: u64,
    /// The end-of-file address the superblock states: the file's size when complete.
    eof: u64,
}

/// A problem found at an address, before the dataset it concerns is known.
type Found<T> = std::result::Result<T, String>;

/// Reads little-endian fields from a byte slice, every read checked.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// File offset of `bytes[0]`, for messages.
    origin: usize,
}

impl<'a> Cursor<'a> {
    fn new(bytes: &'a [u8], origin: usize) -> Self {
        Self {
            bytes,
            pos: 0,
            origin,
        }
    }

    fn take(&mut self, n: usize) -> Found<&'a [u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        match end {
            Some(end) => {
                let s = &self.bytes[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(format!(
                "truncated: {n} bytes needed at byte {} but the structure ends at byte {}",
                self.origin + self.pos,
                self.origin + self.bytes.len()
            )),
        }
    }

    fn uint(&mut self, n: usize) -> Found<u64> {
        let b = self.take(n)?;
        Ok(b.iter()
            .rev()
            .take(8)
            .fold(0u64, |acc, &x| (acc << 8) | u64::from(x)))
    }

    fn u8(&mut self) -> Found<u8> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Found<u16> {
        Ok(self.uint(2)? as u16)
    }

    fn u32(&mut self) -> Found<u32> {
        Ok(self.uint(4)? as u32)
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn at(&self) -> usize {
        self.origin + self.pos
    }
}

/// One message of an object header: its type and body.
struct Message<'a> {
    kind: u16,
    flags: u8,
    body: &'a [u8],
    /// File offset of the body.
    at: usize,
}

impl Hdf5File {
    /// Reads and parses `path`'s superblock.
    pub fn read(path: impl AsRef<Path>) -> Result<Hdf5File> {
        let path = path.as_ref();
        let bytes = crate::text::read_file(path)?;
        Self::from_bytes(bytes, path)
    }

    /// Parses the superblock of the file content `bytes`; `path` names the file in errors.
    pub fn from_bytes(bytes: Vec<u8>, path: impl AsRef<Path>) -> Result<Hdf5File> {
        let path = path.as_ref().to_path_buf();
        let mut base = None;
        let mut at = 0usize;
        while at
            .checked_add(SIGNATURE.len())
            .is_some_and(|e| e <= bytes.len())
        {
            if &bytes[at..at + SIGNATURE.len()] == SIGNATURE {
                base = Some(at);
                break;
            }
            at = if at == 0 { 512 } else { at.saturating_mul(2) };
        }
        let Some(base) = base else {
            return Err(DataError::format(
                Location::file(&path),
                "not an HDF5 file: no HDF5 signature at byte 0 or after a user block (a file \
                 cut off, or another format)",
            ));
        };
        let mut file = Hdf5File {
            bytes,
            path,
            base,
            offset_size: 8,
            length_size: 8,
            root: 0,
            eof: 0,
        };
        file.superblock().map_err(|m| {
            DataError::format(
                Location::file(&file.path).with_field("superblock"),
                format!("corrupt HDF5 superblock: {m}"),
            )
        })?;
        Ok(file)
    }

    /// The file this was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn superblock(&mut self) -> Found<()> {
        let mut c = Cursor::new(&self.bytes[self.base..], self.base);
        c.take(8)?;
        let version = c.u8()?;
        let sizes = |o: u8, l: u8| -> Found<(usize, usize)> {
            for s in [o, l] {
                if ![2, 4, 8].contains(&s) {
                    return Err(format!("offset or length size {s}, expected 2, 4 or 8"));
                }
            }
            Ok((usize::from(o), usize::from(l)))
        };
        match version {
            0 | 1 => {
                c.take(4)?; // free-space, root entry, reserved, shared header versions
                let (o, l) = sizes(c.u8()?, c.u8()?)?;
                (self.offset_size, self.length_size) = (o, l);
                c.take(1)?;
                c.take(4)?; // leaf and internal node K
                c.take(4)?; // consistency flags
                if version == 1 {
                    c.take(4)?;
                }
                let base_addr = c.uint(o)?;
                c.take(o)?; // free space
                self.eof = c.uint(o)?;
                c.take(o)?; // driver info
                // Root group symbol table entry: name offset, object header address, ...
                c.take(o)?;
                self.root = c.uint(o)?;
                self.rebase(base_addr)?;
            }
            2 | 3 => {
                let (o, l) = sizes(c.u8()?, c.u8()?)?;
                (self.offset_size, self.length_size) = (o, l);
                c.take(1)?;
                let base_addr = c.uint(o)?;
                c.take(o)?; // extension
                self.eof = c.uint(o)?;
                self.root = c.uint(o)?;
                self.rebase(base_addr)?;
            }
            v => return Err(format!("superblock version {v}, expected 0 to 3")),
        }
        Ok(())
    }

    /// Addresses are relative to the base address, which is the superblock's offset in every
    /// file h5py writes.
    fn rebase(&mut self, base_addr: u64) -> Found<()> {
        match usize::try_from(base_addr) {
            Ok(b) if b == self.base || b == 0 => Ok(()),
            _ => Err(format!(
                "base address {base_addr} differs from the superblock's offset {}",
                self.base
            )),
        }
    }

    fn undefined(&self, addr: u64) -> bool {
        let bits = 8 * self.offset_size;
        addr == if bits >= 64 {
            u64::MAX
        } else {
            (1u64 << bits) - 1
        }
    }

    /// The bytes from address `addr` to the end of the file.
    fn at_addr(&self, addr: u64, what: &str) -> Found<Cursor<'_>> {
        let start = usize::try_from(addr)
            .ok()
            .and_then(|a| a.checked_add(self.base))
            .filter(|&s| s < self.bytes.len());
        match start {
            Some(s) => Ok(Cursor::new(&self.bytes[s..], s)),
            None => Err(format!(
                "{what} at address {addr}, beyond the end of the file ({} bytes)",
                self.bytes.len()
            )),
        }
    }

    /// `len` bytes at address `addr`.
    fn span(&self, addr: u64, len: u64, what: &str) -> Found<(&[u8], usize)> {
        let mut c = self.at_addr(addr, what)?;
        let at = c.at();
        let n = usize::try_from(len).map_err(|_| format!("{what}: length {len} too large"))?;
        let b = c.take(n).map_err(|_| {
            format!(
                "{what} of {len} bytes at address {addr} runs past the end of the file ({} \
                 bytes): a truncated file?",
                self.bytes.len()
            )
        })?;
        Ok((b, at))
    }

    /// The messages of the object header at `addr`, continuation blocks included.
    fn messages(&self, addr: u64) -> Found<Vec<Message<'_>>> {
        let mut c = self.at_addr(addr, "object header")?;
        // The first block and how its messages are laid out: version 2 (an OHDR signature)
        // or version 1.
        let (first, v2_creation_order) = if c.bytes.starts_with(b"OHDR") {
            c.take(4)?;
            let version = c.u8()?;
            if version != 2 {
                return Err(format!("object header version {version}, expected 2"));
            }
            let flags = c.u8()?;
            if flags & 0x20 != 0 {
                c.take(16)?;
            }
            if flags & 0x10 != 0 {
                c.take(4)?;
            }
            let size = c.uint(1 << (flags & 3))?;
            let at = c.at();
            let n = usize::try_from(size).map_err(|_| "object header too large".to_owned())?;
            ((c.take(n)?, at), Some(flags & 0x04 != 0))
        } else {
            let version = c.u8()?;
            if version != 1 {
                return Err(format!(
                    "object header at byte {} has version {version}, expected 1 (or an OHDR \
                     signature)",
                    c.at() - 1
                ));
            }
            c.take(3)?; // reserved, message count
            c.take(4)?; // reference count
            let size = c.u32()?;
            c.take(4)?; // alignment
            let at = c.at();
            ((c.take(size as usize)?, at), None)
        };
        let head = match v2_creation_order {
            Some(true) => 6,
            Some(false) => 4,
            None => 8,
        };
        let mut out = Vec::new();
        let mut blocks = vec![first];
        let mut i = 0;
        while i < blocks.len() {
            if i >= MAX_BLOCKS || out.len() >= MAX_MESSAGES {
                return Err(
                    "too many object header continuation blocks or messages (a cycle?)".into(),
                );
            }
            let (block, at) = blocks[i];
            i += 1;
            let mut m = Cursor::new(block, at);
            while m.remaining() >= head {
                let (kind, len, flags) = match v2_creation_order {
                    Some(creation_order) => {
                        let kind = u16::from(m.u8()?);
                        let len = usize::from(m.u16()?);
                        let flags = m.u8()?;
                        if creation_order {
                            m.u16()?;
                        }
                        (kind, len, flags)
                    }
                    None => {
                        let kind = m.u16()?;
                        let len = usize::from(m.u16()?);
                        let flags = m.u8()?;
                        m.take(3)?;
                        (kind, len, flags)
                    }
                };
                let at = m.at();
                let body = m.take(len)?;
                if kind == MSG_CONTINUATION {
                    let (b, a) = self.continuation(body)?;
                    if v2_creation_order.is_none() {
                        blocks.push((b, a));
                    } else if !b.starts_with(b"OCHK") || b.len() < 8 {
                        return Err(format!(
                            "object header continuation at byte {a} lacks its OCHK signature"
                        ));
                    } else {
                        blocks.push((&b[4..b.len() - 4], a + 4));
                    }
                }
                out.push(Message {
                    kind,
                    flags,
                    body,
                    at,
                });
            }
        }
        Ok(out)
    }

    /// The block a continuation message points at.
    fn continuation(&self, body: &[u8]) -> Found<(&[u8], usize)> {
        let mut c = Cursor::new(body, 0);
        let addr = c.uint(self.offset_size)?;
        let len = c.uint(self.length_size)?;
        self.span(addr, len, "object header continuation")
    }

    /// The object header address of `name` in the group whose header is at `group`.
    fn child(&self, group: u64, name: &str) -> Found<Option<u64>> {
        let messages = self.messages(group)?;
        for m in &messages {
            match m.kind {
                MSG_SYMBOL_TABLE => {
                    let mut c = Cursor::new(m.body, m.at);
                    let btree = c.uint(self.offset_size)?;
                    let heap = c.uint(self.offset_size)?;
                    let heap = self.local_heap(heap)?;
                    let mut visited = 0;
                    return self.btree_find(btree, heap, name, 0, &mut visited);
                }
                MSG_LINK_INFO => {
                    let mut c = Cursor::new(m.body, m.at);
                    c.u8()?;
                    let flags = c.u8()?;
                    if flags & 1 != 0 {
                        c.take(8)?;
                    }
                    let heap = c.uint(self.offset_size)?;
                    if !self.undefined(heap) {
                        return Err(
                            "the group keeps its links in dense storage (a fractal heap), which \
                             this reader does not support"
                                .into(),
                        );
                    }
                }
                MSG_LINK => {
                    if let Some((link, addr)) = self.link(m)?
                        && link == name.as_bytes()
                    {
                        return addr.map(Some).ok_or_else(|| {
                            format!("`{name}` is a soft or external link, not supported")
                        });
                    }
                }
                _ => {}
            }
        }
        Ok(None)
    }

    /// A link message: the name and, for a hard link, the object address.
    fn link<'b>(&self, m: &Message<'b>) -> Found<Option<(&'b [u8], Option<u64>)>> {
        let mut c = Cursor::new(m.body, m.at);
        let version = c.u8()?;
        if version != 1 {
            return Err(format!("link message version {version}, expected 1"));
        }
        let flags = c.u8()?;
        let kind = if flags & 0x08 != 0 { c.u8()? } else { 0 };
        if flags & 0x04 != 0 {
            c.take(8)?;
        }
        if flags & 0x10 != 0 {
            c.u8()?;
        }
        let len = c.uint(1 << (flags & 3))?;
        let len = usize::try_from(len).map_err(|_| "link name too long".to_owned())?;
        let name = c.take(len)?;
        let addr = if kind == 0 {
            Some(c.uint(self.offset_size)?)
        } else {
            None
        };
        Ok(Some((name, addr)))
    }

    /// The data segment of the local heap at `addr`.
    fn local_heap(&self, addr: u64) -> Found<(&[u8], usize)> {
        let mut c = self.at_addr(addr, "local heap")?;
        if c.take(4)? != b"HEAP" {
            return Err(format!(
                "no local heap (HEAP signature) at byte {}",
                c.at() - 4
            ));
        }
        c.take(4)?;
        let size = c.uint(self.length_size)?;
        c.uint(self.length_size)?;
        let data = c.uint(self.offset_size)?;
        self.span(data, size, "local heap data")
    }

    /// A NUL-terminated name at `offset` in a local heap's data.
    fn heap_name(heap: (&[u8], usize), offset: u64) -> Found<&[u8]> {
        let (data, at) = heap;
        let rest = usize::try_from(offset)
            .ok()
            .and_then(|o| data.get(o..))
            .ok_or_else(|| {
                format!(
                    "name offset {offset} beyond the local heap at byte {at} ({} bytes)",
                    data.len()
                )
            })?;
        let end = rest
            .iter()
            .position(|&b| b == 0)
            .ok_or_else(|| format!("unterminated name in the local heap at byte {at}"))?;
        Ok(&rest[..end])
    }

    /// Searches the group B-tree node at `addr` (and below) for `name`.
    fn btree_find(
        &self,
        addr: u64,
        heap: (&[u8], usize),
        name: &str,
        depth: usize,
        visited: &mut usize,
    ) -> Found<Option<u64>> {
        *visited += 1;
        if depth > MAX_BTREE_DEPTH || *visited > MAX_NODES {
            return Err("group B-tree too deep or cyclic".into());
        }
        let mut c = self.at_addr(addr, "group B-tree node")?;
        let start = c.at();
        if c.take(4)? != b"TREE" {
            return Err(format!("no B-tree node (TREE signature) at byte {start}"));
        }
        let kind = c.u8()?;
        if kind != 0 {
            return Err(format!(
                "B-tree node at byte {start} has type {kind}, expected 0 (group)"
            ));
        }
        let level = c.u8()?;
        let used = c.u16()?;
        c.take(2 * self.offset_size)?;
        for _ in 0..used {
            c.uint(self.length_size)?; // key
            let child = c.uint(self.offset_size)?;
            let found = if level == 0 {
                self.symbol_node_find(child, heap, name, visited)?
            } else {
                self.btree_find(child, heap, name, depth + 1, visited)?
            };
            if found.is_some() {
                return Ok(found);
            }
        }
        Ok(None)
    }

    /// Searches the symbol table node at `addr` for `name`.
    fn symbol_node_find(
        &self,
        addr: u64,
        heap: (&[u8], usize),
        name: &str,
        visited: &mut usize,
    ) -> Found<Option<u64>> {
        let mut c = self.at_addr(addr, "symbol table node")?;
        let start = c.at();
        if c.take(4)? != b"SNOD" {
            return Err(format!(
                "no symbol table node (SNOD signature) at byte {start}"
            ));
        }
        c.take(2)?;
        let count = c.u16()?;
        for _ in 0..count {
            *visited += 1;
            if *visited > MAX_NODES {
                return Err("group too large or cyclic".into());
            }
            let name_offset = c.uint(self.offset_size)?;
            let header = c.uint(self.offset_size)?;
            c.take(8 + 16)?;
            if Self::heap_name(heap, name_offset)? == name.as_bytes() {
                return Ok(Some(header));
            }
        }
        Ok(None)
    }

    /// The object header address of the object at `path` (`synced/acce`), `None` when a
    /// component does not exist.
    fn find(&self, path: &str) -> Found<Option<u64>> {
        let mut at = self.root;
        for (depth, part) in path.split('/').filter(|p| !p.is_empty()).enumerate() {
            if depth >= MAX_PATH_DEPTH {
                return Err("path nested too deep".into());
            }
            match self.child(at, part)? {
                Some(a) => at = a,
                None => return Ok(None),
            }
        }
        Ok(Some(at))
    }

    /// A file shorter than its superblock says was cut off (a download or copy cut short):
    /// an error naming `dataset`, the one being read, rather than whatever the cut breaks.
    fn check_size(&self, dataset: &str) -> Result<()> {
        let have = (self.bytes.len() - self.base) as u64;
        if have < self.eof {
            return Err(self.error(
                dataset,
                format!(
                    "the file is truncated: its superblock says {} bytes, it has {have} (a \
                     download or copy cut short?)",
                    self.eof
                ),
            ));
        }
        Ok(())
    }

    fn error(&self, dataset: &str, message: impl Into<String>) -> DataError {
        DataError::format(
            Location::file(&self.path).with_field(dataset),
            message.into(),
        )
    }

    /// Whether a dataset or group exists at `path`.
    ///
    /// # Errors
    /// When the groups on the way are corrupt.
    pub fn contains(&self, path: &str) -> Result<bool> {
        self.check_size(path)?;
        self.find(path)
            .map(|a| a.is_some())
            .map_err(|m| self.error(path, format!("corrupt HDF5 file: {m}")))
    }

    /// The dataset at `path` as `f64`s, or `None` when there is no object at `path`.
    ///
    /// # Errors
    /// A corrupt file, or an object that is not a floating-point dataset stored contiguously or
    /// compactly; the error names the file and the dataset.
    pub fn read_f64(&self, path: &str) -> Result<Option<Hdf5Array>> {
        self.check_size(path)?;
        let addr = match self.find(path) {
            Ok(Some(a)) => a,
            Ok(None) => return Ok(None),
            Err(m) => return Err(self.error(path, format!("corrupt HDF5 file: {m}"))),
        };
        self.dataset(addr)
            .map(Some)
            .map_err(|m| self.error(path, m))
    }

    fn dataset(&self, addr: u64) -> Found<Hdf5Array> {
        let messages = self
            .messages(addr)
            .map_err(|m| format!("corrupt HDF5 file: {m}"))?;
        let find = |kind: u16| messages.iter().find(|m| m.kind == kind);
        if find(MSG_SYMBOL_TABLE).is_some()
            || find(MSG_LINK_INFO).is_some()
            || find(MSG_LINK).is_some()
        {
            return Err("is a group, expected a dataset".into());
        }
        let (Some(space), Some(dtype), Some(layout)) =
            (find(MSG_DATASPACE), find(MSG_DATATYPE), find(MSG_LAYOUT))
        else {
            return Err(
                "is not a dataset (its object header lacks a dataspace, datatype or \
                        layout message)"
                    .into(),
            );
        };
        if find(MSG_FILTERS).is_some() {
            return Err(
                "is filtered (compressed): only unfiltered datasets are supported, as h5py writes \
                 by default"
                    .into(),
            );
        }
        for m in [space, dtype, layout] {
            if m.flags & 0x02 != 0 {
                return Err(
                    "uses a shared (committed) message, which this reader does not support".into(),
                );
            }
        }
        let shape = self
            .dataspace(space)
            .map_err(|m| format!("corrupt dataspace: {m}"))?;
        let (size, big_endian) = float_type(dtype)?;
        let count = shape
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .filter(|&n| n.checked_mul(size).is_some())
            .ok_or_else(|| format!("shape {shape:?} too large"))?;
        let bytes = self.layout(layout, count * size)?;
        let data = bytes
            .chunks_exact(size)
            .map(|b| {
                let mut a = [0u8; 8];
                a[..size].copy_from_slice(b);
                if big_endian {
                    a[..size].reverse();
                }
                if size == 8 {
                    f64::from_le_bytes(a)
                } else {
                    f64::from(f32::from_le_bytes([a[0], a[1], a[2], a[3]]))
                }
            })
            .collect();
        Ok(Hdf5Array { shape, data })
    }

    fn dataspace(&self, m: &Message<'_>) -> Found<Vec<usize>> {
        let mut c = Cursor::new(m.body, m.at);
        let version = c.u8()?;
        let rank = usize::from(c.u8()?);
        let _flags = c.u8()?;
        match version {
            1 => {
                c.take(5)?;
            }
            2 => {
                let kind = c.u8()?;
                if kind == 2 {
                    return Err("null dataspace (no data)".into());
                }
            }
            v => return Err(format!("version {v}, expected 1 or 2")),
        }
        (0..rank)
            .map(|_| {
                let d = c.uint(self.length_size)?;
                usize::try_from(d).map_err(|_| format!("dimension {d} too large"))
            })
            .collect()
    }

    /// The raw bytes of a dataset of `len` bytes.
    fn layout<'b>(&'b self, m: &Message<'b>, len: usize) -> Found<&'b [u8]> {
        let mut c = Cursor::new(m.body, m.at);
        let version = c.u8()?;
        let class = match version {
            1 | 2 => {
                let rank = usize::from(c.u8()?);
                let class = c.u8()?;
                c.take(5)?;
                if class == 0 {
                    c.take(4 * rank)?;
                    let size = c.u32()? as usize;
                    return compact(c.take(size)?, len);
                }
                if class == 1 {
                    let addr = c.uint(self.offset_size)?;
                    return self.contiguous(addr, len as u64, len);
                }
                class
            }
            3 | 4 => {
                let class = c.u8()?;
                if class == 0 {
                    let size = usize::from(c.u16()?);
                    return compact(c.take(size)?, len);
                }
                if class == 1 {
                    let addr = c.uint(self.offset_size)?;
                    let size = c.uint(self.length_size)?;
                    return self.contiguous(addr, size, len);
                }
                class
            }
            v => return Err(format!("corrupt layout: version {v}, expected 1 to 4")),
        };
        Err(match class {
            2 => "is stored in chunks (h5py's `chunks=`, `compression=` or `maxshape=`): only \
                  contiguous and compact datasets are supported, as h5py writes by default"
                .into(),
            3 => "is a virtual dataset, which this reader does not support".into(),
            c => format!("corrupt layout: storage class {c}"),
        })
    }

    fn contiguous(&self, addr: u64, size: u64, len: usize) -> Found<&[u8]> {
        if len == 0 {
            return Ok(&[]);
        }
        if self.undefined(addr) {
            return Err("holds no data (never written)".into());
        }
        if size < len as u64 {
            return Err(format!(
                "stores {size} bytes, its shape and type need {len}"
            ));
        }
        self.span(addr, len as u64, "dataset data")
            .map(|(b, _)| b)
            .map_err(|m| format!("corrupt HDF5 file: {m}"))
    }
}

/// The data of a compact dataset.
fn compact(data: &[u8], len: usize) -> Found<&[u8]> {
    data.get(..len).ok_or_else(|| {
        format!(
            "compact data holds {} bytes, its shape and type need {len}",
            data.len()
        )
    })
}

/// The element size and byte order of an IEEE floating-point datatype message.
fn float_type(m: &Message<'_>) -> Found<(usize, bool)> {
    let mut c = Cursor::new(m.body, m.at);
    let class_version = c.u8().map_err(|e| format!("corrupt datatype: {e}"))?;
    let bits = c.take(3).map_err(|e| format!("corrupt datatype: {e}"))?;
    let size = c.u32().map_err(|e| format!("corrupt datatype: {e}"))? as usize;
    let class = class_version & 0x0f;
    let name = match class {
        0 => "integer",
        1 => "float",
        2 => "time",
        3 => "string",
        4 => "bitfield",
        5 => "opaque",
        6 => "compound",
        7 => "reference",
        8 => "enum",
        9 => "variable-length",
        10 => "array",
        _ => "unknown",
    };
    if class != 1 || !(size == 4 || size == 8) || bits[0] & 0x40 != 0 {
        return Err(format!(
            "has type {name} of {size} bytes, expected 64-bit (or 32-bit) floats"
        ));
    }
    Ok((size, bits[0] & 1 != 0))
}
