//! Files read and written through a fixed buffer, with exact I/O counters: bytes, system read
//! and write calls, and seeks (each a system call, which seed 000 §4.2.1 counts as a cost).

use serde::Serialize;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::Path;

/// Exact I/O counts of one engine or workload.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct IoCounters {
    pub bytes_read: u64,
    pub bytes_written: u64,
    pub read_calls: u64,
    pub write_calls: u64,
    pub seeks: u64,
}

impl IoCounters {
    pub fn add(&mut self, o: &IoCounters) {
        self.bytes_read += o.bytes_read;
        self.bytes_written += o.bytes_written;
        self.read_calls += o.read_calls;
        self.write_calls += o.write_calls;
        self.seeks += o.seeks;
    }
}

/// A file with its own buffer of a fixed size, reading forward (with forward seeks) or
/// writing sequentially, counting every system call it makes.
pub struct IoFile {
    file: File,
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
        Ok(Self::new(File::open(path)?, buffer))
    }

    pub fn create(path: &Path, buffer: usize) -> io::Result<IoFile> {
        Ok(Self::new(File::create(path)?, buffer))
    }

    fn new(file: File, buffer: usize) -> IoFile {
        IoFile {
            file,
            buf: vec![0; buffer.max(64)],
            pos: 0,
            len: 0,
            base: 0,
            io: IoCounters::default(),
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
        self.file.seek(SeekFrom::Start(offset))?;
        self.io.seeks += 1;
        self.base = offset;
        self.pos = 0;
        self.len = 0;
        Ok(())
    }

    fn fill(&mut self) -> io::Result<usize> {
        self.base += self.len as u64;
        self.pos = 0;
        self.len = 0;
        let n = self.file.read(&mut self.buf)?;
        self.io.read_calls += 1;
        self.io.bytes_read += n as u64;
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
            self.file.write_all(&self.buf[..self.len])?;
            self.io.write_calls += 1;
            self.io.bytes_written += self.len as u64;
            self.base += self.len as u64;
            self.len = 0;
        }
        Ok(())
    }

    /// Flushes and syncs: a full disk shows here at the latest.
    pub fn finish(mut self) -> io::Result<IoCounters> {
        self.flush()?;
        self.file.sync_data()?;
        Ok(self.io)
    }
}
