//! The compressed split layout: `bbox.bin` and `geometry.bin` stored as independently
//! zstd-compressed blocks, so that the seeks of seed 000 §4.2.1–4.2.2 (B's subtree skips, G's lazy
//! geometry loads, shading's `skip_to`) still land anywhere. A basic store is compressed as one
//! stream (it is read strictly forward, §3.4); a split one cannot be: a forward seek there would
//! decompress everything it skips.
//!
//! Files, for each of `bbox.bin` and `geometry.bin` (`NAME`):
//! - `NAME.zst`: one zstd frame (RFC 8878, with its content checksum) per block of at most
//!   [`BLOCK_BYTES`] uncompressed bytes, one after the other. The uncompressed bytes are exactly
//!   the plain file's, so every reader keeps its logical offsets (bbox record id × 36 + 16, the
//!   geometry offsets the bbox records hold).
//! - `NAME.idx`: 16-byte header (magic `RTBIDX\0\0`, u32 version, u32 CRC-32 of `header.json`,
//!   patched in when the store is finished, as the plain files' headers are), then one
//!   [`INDEX_ENTRY`]-byte entry per block: u64 uncompressed offset, u64 compressed offset, u32
//!   uncompressed length, u32 CRC-32 of the entry's first 20 bytes.
//!
//! A block ends when the writer's buffer is full and at every checkpoint of a segmented write
//! ([`super::segments`]), so a resumed write cuts both files back to the checkpoint and goes on.
//! Reading holds one block (the current one, cached: a seek inside it costs nothing), its
//! compressed bytes and the index (16 bytes per block in memory): a seek elsewhere reads and
//! decompresses only the block it lands in.

use super::VERSION;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

pub const INDEX_MAGIC: &[u8; 8] = b"RTBIDX\0\0";
/// Uncompressed bytes of a full block: 128 KiB, so that the index of a 10^9-object store
/// (~100 GB of records, ~800,000 blocks) holds about 12 MB in memory, inside the thesis runs'
/// 320 MiB peak-RSS bound beside `memory=256MiB`.
pub const BLOCK_BYTES: usize = 1 << 17;
pub const INDEX_ENTRY: usize = 24;
const INDEX_HEADER: u64 = 16;

/// The compressed data file of a split file `name` (`bbox.bin` → `bbox.bin.zst`).
pub fn data_name(name: &str) -> String {
    format!("{name}.zst")
}

/// The block index beside a data file (`bbox.bin.zst` → `bbox.bin.idx`).
pub fn index_path(data: &Path) -> PathBuf {
    data.with_extension("idx")
}

fn invalid(path: &Path, what: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: {what}", path.display()),
    )
}

/// Largest compressed size of a block (zstd's bound): no index entry claiming more is believed.
fn max_compressed() -> u64 {
    zstd::zstd_safe::compress_bound(BLOCK_BYTES) as u64
}

fn entry(uoff: u64, coff: u64, ulen: u32) -> [u8; INDEX_ENTRY] {
    let mut e = [0u8; INDEX_ENTRY];
    e[..8].copy_from_slice(&uoff.to_le_bytes());
    e[8..16].copy_from_slice(&coff.to_le_bytes());
    e[16..20].copy_from_slice(&ulen.to_le_bytes());
    let crc = crc32fast::hash(&e[..20]);
    e[20..].copy_from_slice(&crc.to_le_bytes());
    e
}

/// The blocks of one data file: where each starts, uncompressed and compressed.
#[derive(Clone, Debug, Default)]
pub struct BlockIndex {
    pub uoff: Vec<u64>,
    pub coff: Vec<u64>,
    /// Uncompressed bytes in all (the plain file's size).
    pub total: u64,
    /// Bytes of the data file.
    pub stored: u64,
    /// The CRC-32 of `header.json` in the index's header (0 until the store is finished).
    pub header_crc: u32,
}

impl BlockIndex {
    /// Reads `idx` and checks it: its header, every entry's checksum, that the blocks tile the
    /// uncompressed stream from 0 and the data file (`stored` bytes) from 0, each within the
    /// bounds a block can have. With `upto`, only the entries of blocks starting before that
    /// compressed offset are taken (a resumed write's checkpoint), and `stored` is that offset.
    fn read_checked(idx: &Path, stored: u64, upto: bool) -> io::Result<BlockIndex> {
        let f = File::open(idx)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", idx.display())))?;
        let len = f.metadata()?.len();
        // A resumed write may find part of an entry a stopped process left after the
        // checkpoint: it is cut off with the rest.
        if len < INDEX_HEADER || (!upto && !(len - INDEX_HEADER).is_multiple_of(INDEX_ENTRY as u64))
        {
            return Err(invalid(
                idx,
                format!("{len} bytes: not a block index (truncated?)"),
            ));
        }
        let mut r = io::BufReader::with_capacity(1 << 16, f);
        let mut h = [0u8; INDEX_HEADER as usize];
        r.read_exact(&mut h)?;
        if &h[..8] != INDEX_MAGIC || u32::from_le_bytes(h[8..12].try_into().unwrap()) != VERSION {
            return Err(invalid(idx, "not a block index (magic or version)"));
        }
        let n = (len - INDEX_HEADER) / INDEX_ENTRY as u64;
        let mut ix = BlockIndex {
            header_crc: u32::from_le_bytes(h[12..16].try_into().unwrap()),
            stored,
            ..Default::default()
        };
        let mut e = [0u8; INDEX_ENTRY];
        let (mut unext, mut cnext) = (0u64, 0u64);
        for i in 0..n {
            r.read_exact(&mut e)?;
            let u = u64::from_le_bytes(e[..8].try_into().unwrap());
            let c = u64::from_le_bytes(e[8..16].try_into().unwrap());
            let ulen = u32::from_le_bytes(e[16..20].try_into().unwrap()) as u64;
            if crc32fast::hash(&e[..20]) != u32::from_le_bytes(e[20..].try_into().unwrap()) {
                return Err(invalid(idx, format!("entry {i}: checksum mismatch")));
            }
            if upto && c >= stored {
                break;
            }
            // Each block starts where the one before it ended, uncompressed; compressed, after
            // it, and no further than a block can take.
            let ok = u == unext
                && (1..=BLOCK_BYTES as u64).contains(&ulen)
                && (i == 0 && c == 0 || i > 0 && c > cnext && c - cnext <= max_compressed())
                && c < stored;
            if !ok {
                return Err(invalid(idx, format!("entry {i} disagrees with the blocks before it or with the data file ({stored} bytes)")));
            }
            ix.uoff.push(u);
            ix.coff.push(c);
            unext = u + ulen;
            cnext = c;
        }
        let last = ix.coff.last().map_or(0, |&c| stored - c);
        if (ix.coff.is_empty() && stored != 0) || last > max_compressed() {
            return Err(invalid(
                idx,
                format!("the data file ({stored} bytes) does not end with the last block"),
            ));
        }
        ix.total = unext;
        Ok(ix)
    }

    /// The index of a finished data file of `stored` bytes.
    pub fn read(idx: &Path, stored: u64) -> io::Result<BlockIndex> {
        Self::read_checked(idx, stored, false)
    }

    pub fn len(&self) -> usize {
        self.uoff.len()
    }

    pub fn is_empty(&self) -> bool {
        self.uoff.is_empty()
    }

    /// The block holding uncompressed offset `offset`, if any.
    pub fn block_of(&self, offset: u64) -> Option<usize> {
        if offset >= self.total {
            return None;
        }
        Some(self.uoff.partition_point(|&u| u <= offset) - 1)
    }

    /// Block `i`: (uncompressed offset, uncompressed length, compressed offset, compressed
    /// length).
    fn block(&self, i: usize) -> (u64, usize, u64, usize) {
        let uend = self.uoff.get(i + 1).copied().unwrap_or(self.total);
        let cend = self.coff.get(i + 1).copied().unwrap_or(self.stored);
        (
            self.uoff[i],
            (uend - self.uoff[i]) as usize,
            self.coff[i],
            (cend - self.coff[i]) as usize,
        )
    }

    /// Bytes the index holds in memory.
    pub fn bytes(&self) -> u64 {
        (self.uoff.capacity() + self.coff.capacity()) as u64 * 8
    }
}

/// What loading a block cost.
pub struct Load {
    pub uoff: u64,
    pub ulen: usize,
    pub clen: usize,
    /// Whether the file position had to move (a seek: not the block after the last one read).
    pub seek: bool,
}

/// A block-compressed file being read.
pub struct BlockRead {
    file: File,
    path: PathBuf,
    pub index: BlockIndex,
    dctx: zstd::bulk::Decompressor<'static>,
    scratch: Vec<u8>,
    /// The data file's position (after the last block read).
    fpos: u64,
}

impl BlockRead {
    pub fn open(data: &Path) -> io::Result<BlockRead> {
        let file = File::open(data)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", data.display())))?;
        let stored = file.metadata()?.len();
        let index = BlockIndex::read(&index_path(data), stored)?;
        Ok(BlockRead {
            file,
            path: data.to_path_buf(),
            index,
            dctx: zstd::bulk::Decompressor::new()?,
            scratch: Vec::new(),
            fpos: 0,
        })
    }

    /// Reads and decompresses block `i` into `out` (at least [`BLOCK_BYTES`] long), checking its
    /// length against the index and its content against the frame's checksum.
    pub fn load(&mut self, i: usize, out: &mut [u8]) -> io::Result<Load> {
        let (uoff, ulen, coff, clen) = self.index.block(i);
        let seek = coff != self.fpos;
        if seek {
            self.file.seek(SeekFrom::Start(coff))?;
        }
        self.scratch.resize(clen, 0);
        self.file
            .read_exact(&mut self.scratch)
            .map_err(|e| match e.kind() {
                io::ErrorKind::UnexpectedEof => invalid(&self.path, format!("block {i} truncated")),
                _ => e,
            })?;
        self.fpos = coff + clen as u64;
        let n = self
            .dctx
            .decompress_to_buffer(&self.scratch[..], &mut out[..BLOCK_BYTES])
            .map_err(|e| invalid(&self.path, format!("block {i}: {e}")))?;
        if n != ulen {
            return Err(invalid(
                &self.path,
                format!("block {i}: {n} bytes, its index says {ulen}"),
            ));
        }
        Ok(Load {
            uoff,
            ulen,
            clen,
            seek,
        })
    }

    /// Bytes held beside the block buffer: the compressed block and the index.
    pub fn held_bytes(&self) -> u64 {
        max_compressed() + self.index.bytes()
    }

    pub fn raw_fd(&self) -> std::os::fd::RawFd {
        use std::os::fd::AsRawFd;
        self.file.as_raw_fd()
    }
}

/// A block-compressed file being written: each [`BlockWrite::block`] is one zstd frame and one
/// index entry.
pub struct BlockWrite {
    data: File,
    idx: File,
    cctx: zstd::bulk::Compressor<'static>,
    scratch: Vec<u8>,
    /// Bytes of the data file and of the index file.
    pub stored: u64,
    pub index_bytes: u64,
    pub calls: u64,
}

impl BlockWrite {
    fn compressor(level: i32) -> io::Result<zstd::bulk::Compressor<'static>> {
        let mut c = zstd::bulk::Compressor::new(level.clamp(1, 19))?;
        // The frame's content checksum: a damaged byte is caught when its block is read.
        c.set_parameter(zstd::zstd_safe::CParameter::ChecksumFlag(true))?;
        Ok(c)
    }

    pub fn create(data: &Path, level: i32) -> io::Result<BlockWrite> {
        let d = File::create(data)?;
        let mut idx = File::create(index_path(data))?;
        let mut h = [0u8; INDEX_HEADER as usize];
        h[..8].copy_from_slice(INDEX_MAGIC);
        h[8..12].copy_from_slice(&VERSION.to_le_bytes());
        idx.write_all(&h)?;
        Ok(BlockWrite {
            data: d,
            idx,
            cctx: Self::compressor(level)?,
            scratch: Vec::new(),
            stored: 0,
            index_bytes: INDEX_HEADER,
            calls: 1,
        })
    }

    /// Takes up a file a checkpoint left `stored` bytes long on disk and `written` bytes long
    /// uncompressed: both files are cut back to it (a block a stopped process left is dropped).
    pub fn append(data: &Path, level: i32, stored: u64, written: u64) -> io::Result<BlockWrite> {
        let d = std::fs::OpenOptions::new().write(true).open(data)?;
        let len = d.metadata()?.len();
        if len < stored {
            return Err(invalid(
                data,
                format!("{len} bytes, its checkpoint says at least {stored}: truncated"),
            ));
        }
        let ip = index_path(data);
        let ix = BlockIndex::read_checked(&ip, stored, true)?;
        if ix.total != written {
            return Err(invalid(
                &ip,
                format!(
                    "the blocks before the checkpoint hold {} bytes, the checkpoint says {written}",
                    ix.total
                ),
            ));
        }
        d.set_len(stored)?;
        let mut d = d;
        d.seek(SeekFrom::Start(stored))?;
        let index_bytes = INDEX_HEADER + (ix.len() * INDEX_ENTRY) as u64;
        let mut idx = std::fs::OpenOptions::new().write(true).open(&ip)?;
        idx.set_len(index_bytes)?;
        idx.seek(SeekFrom::Start(index_bytes))?;
        Ok(BlockWrite {
            data: d,
            idx,
            cctx: Self::compressor(level)?,
            scratch: Vec::new(),
            stored,
            index_bytes,
            calls: 0,
        })
    }

    /// Writes `bytes` (uncompressed offset `uoff`) as one block.
    pub fn block(&mut self, uoff: u64, bytes: &[u8]) -> io::Result<()> {
        debug_assert!(!bytes.is_empty() && bytes.len() <= BLOCK_BYTES);
        self.scratch.resize(max_compressed() as usize, 0);
        let n = self.cctx.compress_to_buffer(bytes, &mut self.scratch[..])?;
        self.data.write_all(&self.scratch[..n])?;
        self.idx
            .write_all(&entry(uoff, self.stored, bytes.len() as u32))?;
        self.stored += n as u64;
        self.index_bytes += INDEX_ENTRY as u64;
        self.calls += 2;
        Ok(())
    }

    pub fn sync(&self) -> io::Result<()> {
        self.data.sync_data()?;
        self.idx.sync_data()
    }

    pub fn raw_fd(&self) -> std::os::fd::RawFd {
        use std::os::fd::AsRawFd;
        self.data.as_raw_fd()
    }
}
