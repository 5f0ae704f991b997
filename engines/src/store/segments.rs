//! Writing a store in segments, across processes: the 10^8–10^9-object scenes of
//! seed 000's Table 4.3 (mount14, 536,870,916 objects; rings368, 1,000,787,041) took the thesis
//! 19–27 hours to generate, longer than one sitting.
//!
//! Every `segment` objects the writer makes its files durable and complete up to that object
//! ([`StoreWriter::checkpoint`]: a compressed file ends its gzip member, so the file is a valid
//! multi-member gzip stream at every checkpoint) and then replaces `segments.json` (written as a
//! temporary and renamed) with the state and one line per finished segment. A later process
//! streams the scene again from its start, passes the shapes already on disk by (generation only,
//! no encoding and no I/O), cuts each file back to the checkpoint (a segment a stopped process
//! left half-written) and goes on. A time budget stops the writer after the first segment that
//! ends past it. Only when the last object is written does `header.json` appear and
//! `segments.json` go: a directory without `header.json` is a store still being written, which
//! every reader refuses.

use super::io::{Codec, IoCounters};
use super::write::WriteState;
use super::{Layout, StoreWriter, HEADER_FILE};
use rtbench_scenes::{Light, Material, ShapeRef, Sink, View};
use serde::{Deserialize, Serialize};
use std::io;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub const SEGMENTS_FILE: &str = "segments.json";

/// One finished segment: the objects written up to its end, the bytes on disk then, and the
/// seconds it took (generation, encoding, compression and writing).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SegmentDone {
    pub objects: u64,
    pub stored_bytes: u64,
    pub written_bytes: u64,
    pub seconds: f64,
}

/// `segments.json`: what is being written and how far it got.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SegmentLog {
    /// The scene's label (`mount14`, a file name …): a resumed run must stream the same scene.
    pub scene: String,
    pub name: String,
    pub layout: String,
    /// `none`, `gzip:LEVEL` or `zstd:LEVEL`.
    pub codec: String,
    /// Objects per segment.
    pub segment: u64,
    pub state: WriteState,
    pub done: Vec<SegmentDone>,
}

fn codec_text(c: Codec) -> String {
    match c {
        Codec::None => "none".into(),
        Codec::Gzip(l) => format!("gzip:{l}"),
        Codec::Zstd(l) => format!("zstd:{l}"),
    }
}

fn codec_of(s: &str) -> Option<Codec> {
    match s {
        "none" => Some(Codec::None),
        _ => match s.split_once(':')? {
            ("gzip", l) => l.parse().ok().map(Codec::Gzip),
            ("zstd", l) => l.parse().ok().map(Codec::Zstd),
            _ => None,
        },
    }
}

fn bad(dir: &Path, what: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: {what}", dir.join(SEGMENTS_FILE).display()),
    )
}

impl SegmentLog {
    /// The log of a store being written in `dir`, if there is one.
    pub fn read(dir: &Path) -> io::Result<Option<SegmentLog>> {
        match std::fs::read(dir.join(SEGMENTS_FILE)) {
            Ok(b) => serde_json::from_slice(&b)
                .map(Some)
                .map_err(|e| bad(dir, format!("not a segment log ({e})"))),
            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e),
        }
    }

    fn write(&self, dir: &Path) -> io::Result<()> {
        let text = serde_json::to_vec_pretty(self).map_err(io::Error::other)?;
        super::write_atomic(&dir.join(SEGMENTS_FILE), &text)
    }
}

/// How a segmented write ended.
#[derive(Debug)]
pub enum Outcome {
    /// Every object written; `header.json` is in place and `segments.json` gone.
    Finished(IoCounters),
    /// Stopped at a checkpoint (the time budget); run again to go on.
    Stopped,
}

/// A [`Sink`] writing a store in segments (see the module's doc).
pub struct SegmentedWriter {
    dir: PathBuf,
    writer: StoreWriter,
    log: SegmentLog,
    /// Shapes of the stream already on disk (passed by) and shapes seen so far.
    skip: u64,
    seen: u64,
    deadline: Option<Instant>,
    stopped: bool,
    segment_start: Instant,
    error: Option<io::Error>,
}

impl SegmentedWriter {
    /// Starts a store in `dir` (created; must hold no store and no segment log).
    pub fn start(
        dir: &Path,
        scene: &str,
        layout: Layout,
        codec: Codec,
        segment: u64,
    ) -> io::Result<SegmentedWriter> {
        if segment == 0 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "a segment of 0 objects",
            ));
        }
        if dir.join(HEADER_FILE).exists() || dir.join(SEGMENTS_FILE).exists() {
            return Err(io::Error::new(
                io::ErrorKind::AlreadyExists,
                format!("{}: holds a store or a store being written", dir.display()),
            ));
        }
        let mut writer = StoreWriter::create_with(dir, scene, layout, codec)?;
        let state = writer.checkpoint()?;
        let log = SegmentLog {
            scene: scene.to_string(),
            name: scene.to_string(),
            layout: layout.name().to_string(),
            codec: codec_text(codec),
            segment,
            state,
            done: Vec::new(),
        };
        log.write(dir)?;
        Ok(Self::new(dir, writer, log))
    }

    /// Takes up the store being written in `dir` (its `segments.json`); `scene` must be the
    /// label it was started with.
    pub fn resume(dir: &Path, scene: &str) -> io::Result<SegmentedWriter> {
        let log = SegmentLog::read(dir)?
            .ok_or_else(|| bad(dir, "missing: no store is being written here"))?;
        if log.scene != scene {
            return Err(bad(dir, format!("written from {}, not {scene}", log.scene)));
        }
        let layout: Layout = log
            .layout
            .parse()
            .map_err(|e| bad(dir, format!("layout {}: {e}", log.layout)))?;
        let codec = codec_of(&log.codec).ok_or_else(|| bad(dir, format!("codec {}", log.codec)))?;
        let writer = StoreWriter::resume(dir, &log.name, layout, codec, &log.state)?;
        let mut w = Self::new(dir, writer, log);
        w.skip = w.log.state.objects;
        Ok(w)
    }

    fn new(dir: &Path, writer: StoreWriter, log: SegmentLog) -> SegmentedWriter {
        SegmentedWriter {
            dir: dir.to_path_buf(),
            writer,
            log,
            skip: 0,
            seen: 0,
            deadline: None,
            stopped: false,
            segment_start: Instant::now(),
            error: None,
        }
    }

    /// Stop at the first checkpoint after `budget` from now.
    pub fn with_budget(mut self, budget: Duration) -> SegmentedWriter {
        // A budget past what an Instant reaches is no deadline.
        self.deadline = Instant::now().checked_add(budget);
        self
    }

    pub fn log(&self) -> &SegmentLog {
        &self.log
    }

    /// Seconds since the last checkpoint (or since this run's first new object): the last,
    /// short segment's time, which no checkpoint logs, when read just before [`Self::finish`].
    pub fn since_checkpoint(&self) -> f64 {
        self.segment_start.elapsed().as_secs_f64()
    }

    /// Objects on disk at the last checkpoint.
    pub fn objects_done(&self) -> u64 {
        self.log.state.objects
    }

    fn end_segment(&mut self) -> io::Result<()> {
        let state = self.writer.checkpoint()?;
        self.log.done.push(SegmentDone {
            objects: state.objects,
            stored_bytes: state.geometry.stored + state.bbox.map_or(0, |b| b.stored),
            written_bytes: state.geometry.written + state.bbox.map_or(0, |b| b.written),
            seconds: self.segment_start.elapsed().as_secs_f64(),
        });
        self.log.state = state;
        self.log.write(&self.dir)?;
        self.segment_start = Instant::now();
        if self.deadline.is_some_and(|d| Instant::now() >= d) {
            self.stopped = true;
        }
        Ok(())
    }

    /// After the stream: the last (short) segment and the header, or the stop.
    pub fn finish(mut self) -> io::Result<Outcome> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.stopped {
            return Ok(Outcome::Stopped);
        }
        if self.seen < self.skip {
            return Err(bad(
                &self.dir,
                format!(
                    "the scene streamed {} objects, fewer than the {} on disk: another scene?",
                    self.seen, self.skip
                ),
            ));
        }
        let io = self.writer.finish()?;
        std::fs::remove_file(self.dir.join(SEGMENTS_FILE))?;
        Ok(Outcome::Finished(io))
    }
}

impl Sink for SegmentedWriter {
    fn background(&mut self, color: glam::DVec3) {
        self.writer.background(color);
    }
    fn view(&mut self, view: &View) {
        self.writer.view(view);
    }
    fn light(&mut self, light: &Light) {
        self.writer.light(light);
    }
    fn material(&mut self, material: &Material) {
        // Also while passing shapes by: the table is built in order of first use.
        self.writer.material(material);
    }
    fn shape(&mut self, shape: ShapeRef<'_>) {
        self.seen += 1;
        if self.seen <= self.skip || self.stopped || self.error.is_some() {
            return;
        }
        if self.seen == self.skip + 1 && self.skip > 0 {
            // The first segment of a resumed run is timed from here, not from the pass over
            // the objects already on disk.
            self.segment_start = Instant::now();
        }
        self.writer.shape(shape);
        if self.writer.objects().is_multiple_of(self.log.segment) {
            if let Err(e) = self.end_segment() {
                self.error = Some(e);
            }
        }
    }
}
