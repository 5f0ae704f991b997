//! Files read and written through a fixed buffer, with exact I/O counters: bytes, system read
//! and write calls, and seeks (each a system call, which seed 000 §4.2.1 counts as a cost).
//!
//! A file may be gzip-compressed ([`Codec::Gzip`]; seed 000 §3.4 read its scene through gzip,
//! Table 3.3): offsets and positions are then those of the uncompressed stream, `bytes_read` /
//! `bytes_written` count the compressed bytes on disk and `codec_bytes` the uncompressed bytes
//! through the codec. A forward seek decompresses and discards; a backward one (a rewind) opens
//! the stream again from its start. zstd ([`Codec::Zstd`]) is offered beside gzip, which is the
//! thesis's. A compressed file may hold several gzip members (RFC 1952 §2.2) or zstd frames (RFC 8878 §3.1) one after the
//! other, read as one stream: a store written in segments across processes ends a member or frame
//! at every segment ([`IoFile::checkpoint`]).

use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use serde::Serialize;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::blocks::{self, BlockRead, BlockWrite};

/// How a file's bytes are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Codec {
    #[default]
    None,
    /// gzip (RFC 1952) at the given level (1 fast … 9 small; gzip's default is 6).
    Gzip(u32),
    /// zstd (RFC 8878) at the given level (1 fast … 19 small; zstd's default is 3).
    Zstd(i32),
}

impl Codec {
    pub fn name(self) -> &'static str {
        match self {
            Codec::None => "none",
            Codec::Gzip(_) => "gzip",
            Codec::Zstd(_) => "zstd",
        }
    }

    /// The basic layout's object file under this codec.
    pub fn objects_file(self) -> &'static str {
        match self {
            Codec::None => super::OBJECTS_FILE,
            Codec::Gzip(_) => super::OBJECTS_FILE_GZ,
            Codec::Zstd(_) => super::OBJECTS_FILE_ZST,
        }
    }

    /// The codec a store header names (`compression`), at the level it was written with where
    /// that matters only for writing.
    pub fn from_header(name: &str) -> Option<Codec> {
        match name {
            "gzip" => Some(Codec::Gzip(6)),
            "zstd" => Some(Codec::Zstd(3)),
            _ => None,
        }
    }
}

/// A reader or writer counting the bytes and calls that reach the file.
struct Counted<F> {
    inner: F,
    bytes: u64,
    calls: u64,
}

impl<F: Read> Read for Counted<F> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.calls += 1;
        self.bytes += n as u64;
        Ok(n)
    }
}

impl<F: Write> Write for Counted<F> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.calls += 1;
        self.bytes += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

fn counted(f: File) -> Counted<File> {
    Counted {
        inner: f,
        bytes: 0,
        calls: 0,
    }
}

/// log2 of the zstd window: 128 KiB.
const ZSTD_WINDOW_LOG: u32 = 17;

type ZstdRead = zstd::stream::read::Decoder<'static, io::BufReader<Counted<File>>>;
type ZstdWrite = zstd::stream::write::Encoder<'static, Counted<File>>;

enum Backing {
    Plain(File),
    GzRead(Box<MultiGzDecoder<Counted<File>>>),
    GzWrite(Box<GzEncoder<Counted<File>>>),
    ZsRead(Box<ZstdRead>),
    ZsWrite(Box<ZstdWrite>),
    /// Independently compressed blocks with an index (the compressed split layout, [`blocks`]).
    BlockRead(Box<BlockRead>),
    BlockWrite(Box<BlockWrite>),
}

/// A reader of a compressed file: every gzip member or zstd frame in turn, as one stream.
fn decoder(codec: Codec, f: File) -> io::Result<Backing> {
    Ok(match codec {
        Codec::None => Backing::Plain(f),
        Codec::Gzip(_) => Backing::GzRead(Box::new(MultiGzDecoder::new(counted(f)))),
        Codec::Zstd(_) => Backing::ZsRead(Box::new(ZstdRead::new(counted(f))?)),
    })
}

/// A writer through the codec, onto `c` (a new file, or one taken up after a checkpoint).
fn encoder(codec: Codec, c: Counted<File>) -> io::Result<Backing> {
    Ok(match codec {
        Codec::None => Backing::Plain(c.inner),
        Codec::Gzip(level) => {
            Backing::GzWrite(Box::new(GzEncoder::new(c, Compression::new(level.min(9)))))
        }
        Codec::Zstd(level) => {
            let mut e = ZstdWrite::new(c, level.clamp(1, 19))?;
            // A frame checksum, as gzip has its CRC-32: a damaged byte is caught at the end.
            e.include_checksum(true)?;
            // A 128 KiB window (level 3 would take 2 MiB or more): the reader's decoder holds
            // one window per open stream, and the engine's memory budget (Table 3.3: 64 MiB in
            // all) has to hold them.
            e.window_log(ZSTD_WINDOW_LOG)?;
            Backing::ZsWrite(Box::new(e))
        }
    })
}

impl Backing {
    /// A decoder's disk counters so far: (bytes, read calls).
    fn decoder_counts(&self) -> (u64, u64) {
        match self {
            Backing::GzRead(d) => (d.get_ref().bytes, d.get_ref().calls),
            Backing::ZsRead(d) => (d.get_ref().get_ref().bytes, d.get_ref().get_ref().calls),
            _ => (0, 0),
        }
    }

    fn raw_fd(&self) -> std::os::fd::RawFd {
        use std::os::fd::AsRawFd;
        match self {
            Backing::Plain(f) => f.as_raw_fd(),
            Backing::GzRead(d) => d.get_ref().inner.as_raw_fd(),
            Backing::GzWrite(e) => e.get_ref().inner.as_raw_fd(),
            Backing::ZsRead(d) => d.get_ref().get_ref().inner.as_raw_fd(),
            Backing::ZsWrite(e) => e.get_ref().inner.as_raw_fd(),
            Backing::BlockRead(b) => b.raw_fd(),
            Backing::BlockWrite(b) => b.raw_fd(),
        }
    }
}

/// Exact I/O counts of one engine or workload.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct IoCounters {
    pub bytes_read: u64,
    pub bytes_written: u64,
    pub read_calls: u64,
    pub write_calls: u64,
    pub seeks: u64,
    /// Uncompressed bytes through a codec (0 for plain files).
    pub codec_bytes: u64,
}

impl IoCounters {
    pub fn add(&mut self, o: &IoCounters) {
        self.bytes_read += o.bytes_read;
        self.bytes_written += o.bytes_written;
        self.read_calls += o.read_calls;
        self.write_calls += o.write_calls;
        self.seeks += o.seeks;
        self.codec_bytes += o.codec_bytes;
    }

    /// Takes `o` away (counts already in `self`: nothing goes below zero).
    pub fn sub(&mut self, o: &IoCounters) {
        self.bytes_read = self.bytes_read.saturating_sub(o.bytes_read);
        self.bytes_written = self.bytes_written.saturating_sub(o.bytes_written);
        self.read_calls = self.read_calls.saturating_sub(o.read_calls);
        self.write_calls = self.write_calls.saturating_sub(o.write_calls);
        self.seeks = self.seeks.saturating_sub(o.seeks);
        self.codec_bytes = self.codec_bytes.saturating_sub(o.codec_bytes);
    }
}

/// A file with its own buffer of a fixed size, reading forward (with forward seeks) or
/// writing sequentially, counting every system call it makes.
pub struct IoFile {
    file: Backing,
    codec: Codec,
    path: PathBuf,
    /// Disk bytes and calls of compressed streams already closed (a rewind reopens).
    done_bytes: u64,
    done_calls: u64,
    buf: Vec<u8>,
    /// Reading: `buf[pos..len]` is unread. Writing: `buf[..len]` is unwritten.
    pos: usize,
    len: usize,
    /// File offset of `buf[0]` (reading) or of the next byte to write.
    base: u64,
    pub io: IoCounters,
}

impl IoFile {
    pub fn open(path: &Path, buffer: usize) -> io::Result<IoFile> {
        Self::open_codec(path, buffer, Codec::None)
    }

    pub fn create(path: &Path, buffer: usize) -> io::Result<IoFile> {
        Self::create_codec(path, buffer, Codec::None)
    }

    pub fn open_codec(path: &Path, buffer: usize, codec: Codec) -> io::Result<IoFile> {
        let f = File::open(path)?;
        let file = decoder(codec, f)?;
        Ok(Self::new(file, codec, path, buffer))
    }

    pub fn create_codec(path: &Path, buffer: usize, codec: Codec) -> io::Result<IoFile> {
        let file = encoder(codec, counted(File::create(path)?))?;
        Ok(Self::new(file, codec, path, buffer))
    }

    /// A block-compressed file ([`blocks`]: `path` is the data file, its index beside it). The
    /// buffer is one block, whatever was asked: a block is decompressed whole.
    pub fn open_blocks(path: &Path) -> io::Result<IoFile> {
        let b = BlockRead::open(path)?;
        Ok(Self::new(
            Backing::BlockRead(Box::new(b)),
            Codec::Zstd(3),
            path,
            blocks::BLOCK_BYTES,
        ))
    }

    /// A new block-compressed file at zstd `level`: each full buffer is one block.
    pub fn create_blocks(path: &Path, level: i32) -> io::Result<IoFile> {
        let b = BlockWrite::create(path, level)?;
        let mut f = Self::new(
            Backing::BlockWrite(Box::new(b)),
            Codec::Zstd(level),
            path,
            blocks::BLOCK_BYTES,
        );
        f.io.bytes_written = 16;
        f.io.write_calls = 1;
        Ok(f)
    }

    /// As [`IoFile::append_codec`], for a block-compressed file: its data file `stored` bytes
    /// long and its index cut back to the checkpoint.
    pub fn append_blocks(path: &Path, level: i32, stored: u64, written: u64) -> io::Result<IoFile> {
        let b = BlockWrite::append(path, level, stored, written)?;
        let bytes = b.stored + b.index_bytes;
        let mut f = Self::new(
            Backing::BlockWrite(Box::new(b)),
            Codec::Zstd(level),
            path,
            blocks::BLOCK_BYTES,
        );
        f.base = written;
        f.io.bytes_written = bytes;
        Ok(f)
    }

    /// The uncompressed size of a block-compressed file being read (its index's).
    pub fn block_total(&self) -> Option<u64> {
        match &self.file {
            Backing::BlockRead(b) => Some(b.index.total),
            _ => None,
        }
    }

    /// Bytes this file holds in memory: its buffer, and for a block-compressed file the
    /// compressed block and the index.
    pub fn held_bytes(&self) -> u64 {
        self.buf.len() as u64
            + match &self.file {
                Backing::BlockRead(b) => b.held_bytes(),
                _ => 0,
            }
    }

    /// Takes up writing a file that a [`IoFile::checkpoint`] left `stored` bytes long on disk,
    /// `written` bytes of the stream (uncompressed) long: anything after the checkpoint (half a
    /// segment of a process that stopped) is cut off, and writing goes on from there (in a
    /// compressed file, as a new gzip member). The counters start at the file's size, so that
    /// `bytes_written` stays the file's size on disk.
    pub fn append_codec(
        path: &Path,
        buffer: usize,
        codec: Codec,
        stored: u64,
        written: u64,
    ) -> io::Result<IoFile> {
        let mut f = std::fs::OpenOptions::new().write(true).open(path)?;
        let len = f.metadata()?.len();
        if len < stored {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "{}: {len} bytes, its checkpoint says at least {stored}: truncated",
                    path.display()
                ),
            ));
        }
        f.set_len(stored)?;
        f.seek(SeekFrom::Start(stored))?;
        let file = encoder(
            codec,
            Counted {
                inner: f,
                bytes: stored,
                calls: 0,
            },
        )?;
        let mut io = Self::new(file, codec, path, buffer);
        io.base = written;
        io.io.bytes_written = stored;
        Ok(io)
    }

    /// Makes everything written so far durable and complete on its own: flushes the buffer,
    /// ends the gzip member (a compressed file) and starts the next one, and syncs. Returns the
    /// file's size on disk, from which [`IoFile::append_codec`] can take writing up again.
    pub fn checkpoint(&mut self) -> io::Result<u64> {
        self.flush()?;
        let dup = match &self.file {
            Backing::Plain(f) => {
                f.sync_data()?;
                return Ok(self.io.bytes_written);
            }
            // The flush ended a block; the data file's size is the checkpoint.
            Backing::BlockWrite(b) => {
                b.sync()?;
                return Ok(b.stored);
            }
            Backing::GzWrite(e) => e.get_ref().inner.try_clone()?,
            Backing::ZsWrite(e) => e.get_ref().inner.try_clone()?,
            Backing::GzRead(_) | Backing::ZsRead(_) | Backing::BlockRead(_) => {
                return Err(io::Error::other("checkpoint of a file being read"))
            }
        };
        // End the member or frame, then start the next one on the same file.
        let c = match std::mem::replace(&mut self.file, Backing::Plain(dup)) {
            Backing::GzWrite(e) => e.finish()?,
            Backing::ZsWrite(e) => e.finish()?,
            _ => unreachable!("matched above"),
        };
        c.inner.sync_data()?;
        let stored = c.bytes;
        self.io.write_calls = c.calls;
        self.io.bytes_written = stored;
        self.file = encoder(self.codec, c)?;
        Ok(stored)
    }

    fn new(file: Backing, codec: Codec, path: &Path, buffer: usize) -> IoFile {
        IoFile {
            file,
            codec,
            path: path.to_path_buf(),
            done_bytes: 0,
            done_calls: 0,
            buf: vec![0; buffer.max(64)],
            pos: 0,
            len: 0,
            base: 0,
            io: IoCounters::default(),
        }
    }

    /// Asks the kernel to drop the file's pages from the page cache (`posix_fadvise`,
    /// `POSIX_FADV_DONTNEED`), so the next read of them comes from the disk: the thesis's machine
    /// had far less memory than the scene (seed 000 §4.4, 256 MB), this one could cache it all.
    /// Advice only: an error is ignored (the figures then say warm).
    pub fn drop_cache(&self) {
        let fd = self.file.raw_fd();
        // SAFETY: a plain system call on a descriptor this value owns.
        unsafe {
            libc::posix_fadvise(fd, 0, 0, libc::POSIX_FADV_DONTNEED);
        }
    }

    /// Offset of the next byte `read_exact` returns.
    pub fn position(&self) -> u64 {
        self.base + self.pos as u64
    }

    /// Back to the start (one seek), for the next sweep.
    pub fn rewind(&mut self) -> io::Result<()> {
        self.seek_to(0)
    }

    /// Moves the read position to `offset`: inside the buffer without a system call, else one
    /// seek.
    pub fn seek_to(&mut self, offset: u64) -> io::Result<()> {
        if offset >= self.base && offset <= self.base + self.len as u64 {
            self.pos = (offset - self.base) as usize;
            return Ok(());
        }
        match &mut self.file {
            Backing::Plain(f) => {
                f.seek(SeekFrom::Start(offset))?;
                self.io.seeks += 1;
                self.base = offset;
                self.pos = 0;
                self.len = 0;
                Ok(())
            }
            Backing::GzRead(_) | Backing::ZsRead(_) => {
                if offset < self.base {
                    // Back: the stream again from its start.
                    let (bytes, calls) = self.file.decoder_counts();
                    self.done_bytes += bytes;
                    self.done_calls += calls;
                    self.file = decoder(self.codec, File::open(&self.path)?)?;
                    self.io.seeks += 1;
                    self.base = 0;
                    self.pos = 0;
                    self.len = 0;
                }
                // Forward: decompress and discard.
                while offset > self.base + self.len as u64 {
                    if self.fill()? == 0 {
                        self.pos = self.len;
                        return Ok(());
                    }
                }
                self.pos = (offset - self.base) as usize;
                Ok(())
            }
            Backing::BlockRead(_) => {
                // Anywhere: the block it lands in, read and decompressed (the one cached in the
                // buffer was checked above).
                let i = match &self.file {
                    Backing::BlockRead(b) => b.index.block_of(offset),
                    _ => unreachable!("matched above"),
                };
                match i {
                    Some(i) => {
                        self.load_block(i)?;
                        self.pos = (offset - self.base) as usize;
                    }
                    None => {
                        // At or past the end: the next read finds nothing.
                        self.base = offset;
                        self.pos = 0;
                        self.len = 0;
                    }
                }
                Ok(())
            }
            Backing::GzWrite(_) | Backing::ZsWrite(_) | Backing::BlockWrite(_) => {
                Err(io::Error::other("seek in a file being written"))
            }
        }
    }

    /// Block `i` of a block-compressed file into the buffer, counted: its compressed bytes, one
    /// read call, a seek when it is not the block after the last one read.
    fn load_block(&mut self, i: usize) -> io::Result<usize> {
        let Backing::BlockRead(b) = &mut self.file else {
            return Err(io::Error::other("not a block-compressed file"));
        };
        let l = b.load(i, &mut self.buf)?;
        self.io.read_calls += 1;
        self.io.bytes_read += l.clen as u64;
        self.io.codec_bytes += l.ulen as u64;
        self.io.seeks += l.seek as u64;
        self.base = l.uoff;
        self.pos = 0;
        self.len = l.ulen;
        Ok(l.ulen)
    }

    fn fill(&mut self) -> io::Result<usize> {
        if let Backing::BlockRead(b) = &self.file {
            let next = self.base + self.len as u64;
            return match b.index.block_of(next) {
                Some(i) => self.load_block(i),
                None => {
                    self.base = next;
                    self.pos = 0;
                    self.len = 0;
                    Ok(0)
                }
            };
        }
        self.base += self.len as u64;
        self.pos = 0;
        self.len = 0;
        let n = match &mut self.file {
            Backing::Plain(f) => {
                let n = f.read(&mut self.buf)?;
                self.io.read_calls += 1;
                self.io.bytes_read += n as u64;
                n
            }
            Backing::GzRead(_) | Backing::ZsRead(_) => {
                // Fill the whole buffer where the stream allows (the decoder returns in pieces).
                let mut n = 0;
                while n < self.buf.len() {
                    let k = match &mut self.file {
                        Backing::GzRead(d) => d.read(&mut self.buf[n..])?,
                        Backing::ZsRead(d) => d.read(&mut self.buf[n..])?,
                        _ => unreachable!("matched a decoder above"),
                    };
                    if k == 0 {
                        break;
                    }
                    n += k;
                }
                let (bytes, calls) = self.file.decoder_counts();
                self.io.read_calls = self.done_calls + calls;
                self.io.bytes_read = self.done_bytes + bytes;
                self.io.codec_bytes += n as u64;
                n
            }
            Backing::BlockRead(_) => unreachable!("read above"),
            Backing::GzWrite(_) | Backing::ZsWrite(_) | Backing::BlockWrite(_) => {
                return Err(io::Error::other("read from a file being written"))
            }
        };
        self.len = n;
        Ok(n)
    }

    /// Fills `out` exactly; `UnexpectedEof` when the file ends first.
    pub fn read_exact(&mut self, mut out: &mut [u8]) -> io::Result<()> {
        while !out.is_empty() {
            if self.pos == self.len && self.fill()? == 0 {
                return Err(io::ErrorKind::UnexpectedEof.into());
            }
            let n = out.len().min(self.len - self.pos);
            out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
            self.pos += n;
            out = &mut out[n..];
        }
        Ok(())
    }

    pub fn write_all(&mut self, mut data: &[u8]) -> io::Result<()> {
        while !data.is_empty() {
            if self.len == self.buf.len() {
                self.flush()?;
            }
            let n = data.len().min(self.buf.len() - self.len);
            self.buf[self.len..self.len + n].copy_from_slice(&data[..n]);
            self.len += n;
            data = &data[n..];
        }
        Ok(())
    }

    /// Bytes written so far (buffered included): the offset of the next record.
    pub fn written(&self) -> u64 {
        self.base + self.len as u64
    }

    pub fn flush(&mut self) -> io::Result<()> {
        if self.len > 0 {
            match &mut self.file {
                Backing::Plain(f) => {
                    f.write_all(&self.buf[..self.len])?;
                    self.io.write_calls += 1;
                    self.io.bytes_written += self.len as u64;
                }
                Backing::GzWrite(e) => {
                    e.write_all(&self.buf[..self.len])?;
                    self.io.codec_bytes += self.len as u64;
                    let c = e.get_ref();
                    self.io.write_calls = c.calls;
                    self.io.bytes_written = c.bytes;
                }
                Backing::ZsWrite(e) => {
                    e.write_all(&self.buf[..self.len])?;
                    self.io.codec_bytes += self.len as u64;
                    let c = e.get_ref();
                    self.io.write_calls = c.calls;
                    self.io.bytes_written = c.bytes;
                }
                Backing::BlockWrite(b) => {
                    b.block(self.base, &self.buf[..self.len])?;
                    self.io.codec_bytes += self.len as u64;
                    self.io.write_calls = b.calls;
                    self.io.bytes_written = b.stored + b.index_bytes;
                }
                Backing::GzRead(_) | Backing::ZsRead(_) | Backing::BlockRead(_) => {
                    return Err(io::Error::other("write to a file being read"))
                }
            }
            self.base += self.len as u64;
            self.len = 0;
        }
        Ok(())
    }

    /// Flushes and syncs: a full disk shows here at the latest.
    pub fn finish(mut self) -> io::Result<IoCounters> {
        self.flush()?;
        match self.file {
            Backing::Plain(f) => f.sync_data()?,
            Backing::GzWrite(e) => {
                let c = e.finish()?;
                self.io.write_calls = c.calls;
                self.io.bytes_written = c.bytes;
                c.inner.sync_data()?;
            }
            Backing::ZsWrite(e) => {
                let c = e.finish()?;
                self.io.write_calls = c.calls;
                self.io.bytes_written = c.bytes;
                c.inner.sync_data()?;
            }
            Backing::BlockWrite(b) => b.sync()?,
            Backing::GzRead(_) | Backing::ZsRead(_) | Backing::BlockRead(_) => {}
        }
        Ok(self.io)
    }
}
