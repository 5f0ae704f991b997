//! A seeded mutation fuzzer over rtbench's readers of outside data: the NFF reader, the
//! scene-store reader, the results reader and the mesh readers (glTF and GLB, PLY ASCII and
//! binary, OBJ). The harness's own readers (history database, suite TOML, shard manifests) are
//! fuzzed by the harness's tests with the same mutations (`mutate`). Each input is a seed from
//! the corpus in
//! `tests/fuzz/corpus/` (store seeds are written from the NFF seeds) with one to four mutations:
//! bit flips, interesting bytes, tokens from a dictionary (`nan`, `1e308`, huge counts …),
//! deleted, repeated or truncated spans. An input passes when the reader returns (a value or an
//! error) without panicking; the slowest input is kept. Aborts end the process, which the caller
//! sees.
//!
//! Small runs are part of `cargo test` (tests/tests/fuzz.rs); large ones:
//! `cargo run --release -p rtbench-tests --example fuzz -- [N] [SEED] [nff|store|results|all]`.

use rtbench_engines::geometry::Geometry;
use rtbench_engines::store::{
    BboxReader, GeometryReader, ObjectRecord, StoreHeader, StoreWriter, BBOX_FILE, GEOMETRY_FILE,
    HEADER_FILE, MATERIALS_FILE,
};
use rtbench_scenes::{nff, SceneCollector};
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Which reader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    Nff,
    Store,
    Results,
    Gltf,
    Ply,
    Obj,
}

impl Target {
    pub const ALL: [Target; 6] = [
        Target::Nff,
        Target::Store,
        Target::Results,
        Target::Gltf,
        Target::Ply,
        Target::Obj,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::Nff => "nff",
            Target::Store => "store",
            Target::Results => "results",
            Target::Gltf => "gltf",
            Target::Ply => "ply",
            Target::Obj => "obj",
        }
    }

    /// The mesh file extensions of a mesh target's seeds.
    fn extensions(self) -> &'static [&'static str] {
        match self {
            Target::Gltf => &["gltf", "glb"],
            Target::Ply => &["ply"],
            Target::Obj => &["obj"],
            _ => &[],
        }
    }
}

/// What a run found.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    pub inputs: u64,
    /// Inputs the reader accepted (the rest it refused with an error).
    pub accepted: u64,
    pub panics: u64,
    /// Store inputs accepted although a byte differs from their seed: a corruption read as good.
    pub corrupt_accepted: u64,
    /// The first input that panicked, with the panic's message.
    pub first_panic: Option<(Vec<u8>, String)>,
    pub slowest: Duration,
    pub elapsed: Duration,
}

/// The fuzzers' generator (`fastrand`'s), seeded: a seed replays its inputs.
pub struct Rng(fastrand::Rng);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(fastrand::Rng::with_seed(seed))
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0.u64(..)
    }
    /// Below `n` (0 when `n` is 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            self.0.usize(..n)
        }
    }
}

const TOKENS: &[&str] = &[
    "../",
    "/etc/passwd",
    "/dev/zero",
    "data:;base64,",
    "5126",
    "5121",
    "\"VEC4\"",
    "\"MAT4\"",
    "\"byteStride\":4,",
    "\"accessors\":[],",
    "\"children\":[0],",
    "element vertex 4294967295\n",
    "property list uchar int vertex_indices\n",
    "\nmtllib /dev/zero\n",
    "\nf 1 2 99999\n",
    "日",
    " nan ",
    " inf ",
    " -inf ",
    " 1e308 ",
    " -1e308 ",
    " 1e30 ",
    " 0 ",
    " -1 ",
    " 4294967296 ",
    " 99999999999999999999 ",
    "\np 16384\n",
    "\np 3\n",
    "\npp 3\n",
    "\nv\n",
    "\ns 0 0 0 0\n",
    "\nc 0 0 0 0 0 0 0 0\n",
    "\u{1b}[31m",
    "\0",
    "#",
    "\"",
    "[",
    "]",
    "{",
    "}",
    ":",
    ",",
    "null",
    "1e999",
    "-0",
    "\u{ff}",
];

/// One to four mutations of `seed`.
pub fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        let len = b.len();
        match rng.below(7) {
            0 if len > 0 => {
                let bit = rng.below(len * 8);
                b[bit / 8] ^= 1 << (bit % 8);
            }
            1 if len > 0 => {
                const BYTES: &[u8] = b"\0\xff-9e. \n.0123456789";
                let i = rng.below(len);
                b[i] = BYTES[rng.below(BYTES.len())];
            }
            2 => {
                let t = TOKENS[rng.below(TOKENS.len())].as_bytes();
                let at = rng.below(len + 1);
                b.splice(at..at, t.iter().copied());
            }
            3 if len > 0 => {
                let at = rng.below(len);
                let n = 1 + rng.below((len - at).min(64));
                b.drain(at..at + n);
            }
            4 if len > 0 => {
                let at = rng.below(len);
                let n = 1 + rng.below((len - at).min(64));
                let span: Vec<u8> = b[at..at + n].to_vec();
                for _ in 0..1 + rng.below(8) {
                    b.splice(at..at, span.iter().copied());
                }
            }
            5 if len > 0 => b.truncate(rng.below(len)),
            _ if len >= 4 => {
                // A little-endian u32 set to an extreme (record lengths, counts).
                let at = rng.below(len - 3);
                let v: u32 = [0, 1, 0xffff_fff0, u32::MAX, 0x8000_0000][rng.below(5)];
                b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
            _ => b.push(rng.next_u64() as u8),
        }
    }
    b
}

/// The seed corpus of `target`, from `corpus` (tests/fuzz/corpus); store seeds are the stores
/// of the NFF seeds that read, written into `work`: (file, bytes) per file of each store.
pub fn seeds(target: Target, corpus: &Path, work: &Path) -> Vec<Vec<(String, Vec<u8>)>> {
    let files = |dir: &str| -> Vec<(String, Vec<u8>)> {
        let mut v: Vec<_> = std::fs::read_dir(corpus.join(dir))
            .unwrap_or_else(|e| panic!("{}: {e}", corpus.join(dir).display()))
            .map(|e| e.unwrap().path())
            .map(|p| (p.display().to_string(), std::fs::read(&p).unwrap()))
            .collect();
        v.sort();
        v
    };
    match target {
        Target::Nff => files("nff").into_iter().map(|f| vec![f]).collect(),
        Target::Results => files("results").into_iter().map(|f| vec![f]).collect(),
        Target::Gltf | Target::Ply | Target::Obj => files("mesh")
            .into_iter()
            .filter(|(name, _)| {
                let ext = Path::new(name).extension().and_then(|e| e.to_str());
                ext.is_some_and(|e| target.extensions().contains(&e))
            })
            .map(|(name, bytes)| {
                let ext = Path::new(&name).extension().unwrap().to_string_lossy();
                vec![(format!("fuzz.{ext}"), bytes)]
            })
            .collect(),
        Target::Store => {
            let mut out = Vec::new();
            for (i, (_, text)) in files("nff").into_iter().enumerate() {
                let dir = work.join(format!("seed-{i}"));
                let _ = std::fs::remove_dir_all(&dir);
                let mut c = SceneCollector::default();
                let Ok(text) = std::str::from_utf8(&text) else {
                    continue;
                };
                if nff::read_nff(text, "seed", &mut c).is_err() || c.scene.objects.is_empty() {
                    continue;
                }
                StoreWriter::create(&dir, "seed")
                    .and_then(|w| w.write_scene(&c.scene))
                    .expect("seed store");
                out.push(
                    [HEADER_FILE, BBOX_FILE, GEOMETRY_FILE, MATERIALS_FILE]
                        .iter()
                        .map(|n| (n.to_string(), std::fs::read(dir.join(n)).unwrap()))
                        .collect(),
                );
                let _ = std::fs::remove_dir_all(&dir);
            }
            out
        }
    }
}

/// Feeds one input to the reader; true when it was accepted.
fn feed(target: Target, files: &[(String, Vec<u8>)], dir: &Path) -> bool {
    match target {
        Target::Nff => {
            let text = String::from_utf8_lossy(&files[0].1);
            let mut c = SceneCollector::default();
            if nff::read_nff(&text, "fuzz", &mut c).is_err() {
                return false;
            }
            // Accepted scenes go on to what engines make of them (triangulation, boxes).
            let _ = Geometry::from_scene(&c.scene);
            true
        }
        Target::Results => {
            let text = String::from_utf8_lossy(&files[0].1);
            match rtbench_reports::results::parse_results(&text, "fuzz") {
                Ok(records) => {
                    let summary = rtbench_reports::Summary::of(None, records);
                    for chart in rtbench_reports::plot::charts(&summary) {
                        let _ = rtbench_reports::plot::svg(&chart);
                    }
                    true
                }
                Err(_) => false,
            }
        }
        Target::Store => {
            for (name, bytes) in files {
                std::fs::write(dir.join(name), bytes).expect("fuzz dir is writable");
            }
            read_store(dir).is_ok()
        }
        Target::Gltf | Target::Ply | Target::Obj => {
            let (name, bytes) = &files[0];
            let path = dir.join(name);
            std::fs::write(&path, bytes).expect("fuzz dir is writable");
            // Accepted meshes go on to the scene a run makes of them.
            let mut c = SceneCollector::default();
            rtbench_scenes::mesh::stream_mesh(&path, &mut c).is_ok()
        }
    }
}

/// What the breadth-first engine and the out-of-core workload do with a store: the header, the
/// full check, then every record through the readers.
fn read_store(dir: &Path) -> std::io::Result<()> {
    let h = StoreHeader::read(dir)?;
    h.verify()?;
    let mut bbox = BboxReader::open(dir, h.objects, 4096)?;
    let mut geometry = GeometryReader::open(dir, 4096)?;
    let mut rec = ObjectRecord::default();
    while let Some((_, b)) = bbox.next_record()? {
        geometry.read_at(b.offset, &mut rec)?;
    }
    Ok(())
}

/// `n` mutated inputs of `target` from seed `seed`.
pub fn run(target: Target, n: u64, seed: u64, corpus: &Path) -> Outcome {
    let work: PathBuf = std::env::temp_dir().join(format!(
        "rtbench-fuzz-{}-{}-{seed}",
        target.name(),
        std::process::id()
    ));
    std::fs::create_dir_all(&work).expect("fuzz work dir");
    let seeds = seeds(target, corpus, &work);
    assert!(!seeds.is_empty(), "no seeds for {}", target.name());
    if target == Target::Gltf {
        // The external buffer `quad-file.gltf` names, beside every input.
        std::fs::copy(corpus.join("mesh/quad.bin"), work.join("quad.bin")).expect("quad.bin");
    }
    if target == Target::Store {
        // Every seed store reads as written: otherwise no mutation could be told from the seed.
        for files in &seeds {
            for (name, bytes) in files {
                std::fs::write(work.join(name), bytes).expect("fuzz dir is writable");
            }
            if let Err(e) = read_store(&work) {
                panic!("a seed store does not read: {e}");
            }
        }
    }
    let mut rng = Rng::new(seed);
    let mut o = Outcome::default();
    let start = Instant::now();
    // Panics are counted, not printed per input.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for _ in 0..n {
        let s = &seeds[rng.below(seeds.len())];
        // Store inputs: one file of the four mutated (so that the others stay plausible).
        let mut files = s.clone();
        let which = rng.below(files.len());
        files[which].1 = mutate(&files[which].1, &mut rng);
        let t = Instant::now();
        let r = std::panic::catch_unwind(AssertUnwindSafe(|| feed(target, &files, &work)));
        o.slowest = o.slowest.max(t.elapsed());
        o.inputs += 1;
        match r {
            Ok(true) => {
                o.accepted += 1;
                if target == Target::Store && files[which].1 != s[which].1 {
                    o.corrupt_accepted += 1;
                }
            }
            Ok(false) => {}
            Err(p) => {
                o.panics += 1;
                if o.first_panic.is_none() {
                    let msg = p
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| p.downcast_ref::<String>().cloned())
                        .unwrap_or_default();
                    o.first_panic = Some((files[which].1.clone(), msg));
                }
            }
        }
    }
    std::panic::set_hook(hook);
    o.elapsed = start.elapsed();
    let _ = std::fs::remove_dir_all(&work);
    o
}

/// The corpus folder of this crate.
pub fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus")
}
