//! The command line. Its names and JSON shapes are a contract that scripts and nightly jobs rely on
//! (docs/concepts.md): extend, never rename.

use clap::{Args, Parser, Subcommand};
use rtbench_scenes::spd::MountHash;
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "rtbench",
    version,
    about = "Benchmark and reproducibility harness for ray-tracing acceleration structures",
    after_help = ENV_HELP
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// The environment variables rtbench reads, as `--help` names them (`rtbench env` says more).
pub const ENV_HELP: &str = "Environment (read once at the start; a malformed value is exit 2; \
`rtbench env` lists the accepted forms): RTBENCH_MAX_THREADS, RTBENCH_PIN_THREADS, RTBENCH_SCHED, \
RTBENCH_BANDS, RTBENCH_MEMORY_PHASES, RTBENCH_PLANT, RTBENCH_BUILD_PHASES, RTBENCH_PLUGIN_DIR, \
RTBENCH_TEST_ENGINES, RTBENCH_TEST_SLOWDOWN.";

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Generate SPD scenes, show their statistics.
    #[command(
        subcommand,
        after_help = "Examples:\n  rtbench scene list\n  rtbench scene gen mount --sf 8 --hash jenkins -o mount8.nff\n  rtbench scene stats bunny.ply --json"
    )]
    Scene(SceneCommand),
    /// List the engines and whether each can run here.
    #[command(after_help = "Examples:\n  rtbench engines\n  rtbench engines --json")]
    Engines {
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
    /// Trace the SPD workload for one scene with one engine.
    #[command(
        after_help = "Examples:\n  rtbench render --scene gears --engine bvh8 --png gears.png                  # trace gears4, save the image\n  rtbench render --scene balls --sf 2 --engine embree --size 128 --json       # ray counts, times, memory as JSON\n  rtbench render --scene mount10/ --engine breadth-first --set memory=32MiB   # out of core, from a scene store"
    )]
    Render(RenderArgs),
    /// Cross-check an engine's hits against Embree or the reference engine on the same rays.
    #[command(
        after_help = "Examples:\n  rtbench check --scene balls --sf 2 --engine bvh8                       # hits against Embree on the same rays\n  rtbench check --scene tetra --engine grid --against reference --json\n  rtbench check --suite hard --engine bvh4,embree --out out/hard         # hard cases, acne, speed against error"
    )]
    Check(CheckArgs),
    /// 001's statistics of a BVH of any width 2–16 (even), built but not traced.
    #[command(
        after_help = "Examples:\n  rtbench tree-stats --scene tree --sf 10 --tessellate --width 16"
    )]
    TreeStats(TreeStatsArgs),
    /// Remeasure a published table: `reproduce list`, `reproduce <id> --out DIR`.
    #[command(
        after_help = "Examples:\n  rtbench reproduce list                                         # every table, its seed, fidelity counts and run time\n  rtbench reproduce spd-stats --engines embree --out out/repro   # writes out/repro/spd-stats.md, .json, .html\n  rtbench reproduce nakamaru-3.1 --quick --out out/repro         # a scaled-down run"
    )]
    Reproduce(ReproduceArgs),
    /// Many engines × scenes × SFs, each run in its own process, results to DIR/results.jsonl.
    #[command(
        after_help = "Examples:\n  rtbench run --engines embree,bvh8 --scenes gears --sf 2 --out out/gears\n  rtbench run --engines bvh4,bvh4:simd=off,embree --scenes standard --paired 5 --out out/simd   # variants, paired with Embree\n  rtbench run --engines all --scenes standard --threads 1,all --out out/all --resume"
    )]
    Run(RunArgs),
    /// Raise each scene's SF until a run passes the time or memory limit.
    #[command(
        after_help = "Examples:\n  rtbench sweep --engines grid,bvh4,embree --scenes balls,tetra --max-seconds 60 --out out/sweep"
    )]
    Sweep(SweepArgs),
    /// Tables and plots from a results directory.
    #[command(
        after_help = "Examples:\n  rtbench report out/gears                   # report.md, report.html, results.csv, summary.json, plots/\n  rtbench report out/gears --format md,csv"
    )]
    Report(ReportArgs),
    /// Compare two results directories; exit 1 on a regression.
    #[command(
        after_help = "Examples:\n  rtbench compare out/yesterday out/today                         # exit 1 on a regression, naming it\n  rtbench compare out/yesterday out/today --threshold 10 --json"
    )]
    Compare(CompareArgs),
    /// One measured run, printed as one JSON line (the child process of run and sweep).
    #[command(hide = true)]
    RunOne(RunOneArgs),
    /// One trace on the calling thread, after an untimed one: the region the nightly's
    /// instruction counts cover under valgrind (its child process).
    #[command(hide = true)]
    CountOne(CountOneArgs),
    /// Run a nightly suite, store every sample in the history, exit 1 on a detected regression.
    #[command(
        after_help = "Examples:\n  rtbench nightly --suite suites/nightly.toml --db out/nightly/history.sqlite --out out/nightly/run1\n  rtbench nightly --suite suites/nightly.toml --shard 1/2 --out out/n1                                 # one shard; merge, then --from\n  rtbench nightly --suite suites/nightly.toml --from out/merged --db out/nightly/history.sqlite"
    )]
    Nightly(NightlyArgs),
    /// The nightly history: list, show, export (CSV, Bencher Metric Format), dashboard.
    #[command(
        subcommand,
        after_help = "Examples:\n  rtbench history list --db out/nightly/history.sqlite\n  rtbench history export --db out/nightly/history.sqlite --format bmf\n  rtbench history dashboard --db out/nightly/history.sqlite --out out/dashboard"
    )]
    History(HistoryCommand),
    /// Join the results of a plan's shards (`--shard K/N`, `render --tile K/N`) into one set.
    #[command(
        after_help = "Examples:\n  rtbench merge out/s1 out/s2 --out out/merged                # the shards of one plan (--shard 1/2, 2/2)\n  rtbench merge out/t1 out/t2 out/t3 out/t4 --out out/image   # the tiles of render --tile K/4"
    )]
    Merge(MergeArgs),
    /// A plan's jobs, groups and shards, without running them (for cluster job arrays).
    #[command(
        after_help = "Examples:\n  rtbench plan run --engines all --scenes standard --out out/all --shards 4\n  rtbench plan --json nightly --suite suites/nightly.toml                     # jobs, groups and slices as JSON"
    )]
    Plan(PlanCmdArgs),
    /// The RTBENCH_* environment variables: each one's value here, accepted forms and effect.
    #[command(after_help = "Examples:\n  rtbench env\n  RTBENCH_MAX_THREADS=2 rtbench env --json")]
    Env {
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
}

#[derive(Args, Debug, Clone)]
pub struct NightlyArgs {
    /// The suite file (TOML; the default suite is suites/nightly.toml).
    #[arg(long)]
    pub suite: PathBuf,
    /// The history (SQLite; created if missing). Required but with --shard.
    #[arg(long)]
    pub db: Option<PathBuf>,
    /// Also write the runs (results.jsonl), the Markdown summary (nightly.md) and the dashboard here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A note stored with the night.
    #[arg(long)]
    pub note: Option<String>,
    /// Compare, but do not write the night to the history.
    #[arg(long)]
    pub no_record: bool,
    /// Skip the suite's criterion benchmarks this time.
    #[arg(long)]
    pub skip_criterion: bool,
    /// Measure only the K-th of N slices of the suite (whole scenes; criterion in shard 1) into
    /// --out DIR, without the history; `rtbench merge` joins the shards and
    /// `rtbench nightly --from MERGED --db F` compares and records them as one night.
    #[arg(long, value_name = "K/N", conflicts_with_all = ["db", "from"])]
    pub shard: Option<String>,
    /// Compare and record a night measured by shards and merged (`rtbench merge`), instead of
    /// measuring here.
    #[arg(long, value_name = "DIR")]
    pub from: Option<PathBuf>,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
}

#[derive(Subcommand, Debug)]
pub enum HistoryCommand {
    /// Every night of the history.
    List {
        /// The history (SQLite file).
        #[arg(long)]
        db: PathBuf,
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
    /// One night (default: the latest): its findings and gated metrics.
    Show {
        /// The history (SQLite file).
        #[arg(long)]
        db: PathBuf,
        /// A night's id, or `latest`.
        #[arg(long)]
        run: Option<String>,
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
    /// Every metric of every night as CSV, or one night (default: the latest) as Bencher Metric Format JSON.
    Export {
        /// The history (SQLite file).
        #[arg(long)]
        db: PathBuf,
        /// `csv` or `bmf`.
        #[arg(long, default_value = "csv")]
        format: String,
        /// A night's id, or `latest` (the default).
        #[arg(long)]
        run: Option<String>,
    },
    /// The detection run again over a suite's nights in the history, each night against the
    /// nights before it, with the suite file's settings: which nights report a regression.
    Replay {
        /// The history (SQLite file).
        #[arg(long)]
        db: PathBuf,
        /// The suite file (its name selects the nights; its settings drive the detection).
        #[arg(long)]
        suite: PathBuf,
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
    /// `PRAGMA integrity_check` of the history, and its nights (exit 1 when not whole).
    Check {
        /// The history (SQLite file).
        #[arg(long)]
        db: PathBuf,
    },
    /// The static HTML dashboard (DIR/index.html) of the history.
    Dashboard {
        /// The history (SQLite file).
        #[arg(long)]
        db: PathBuf,
        /// The folder the dashboard (index.html) is written to.
        #[arg(long)]
        out: PathBuf,
        /// Link each commit id through this URL, `{commit}` replaced by the id (none by default;
        /// a suite's `commit_url` does the same for the nightly's copy).
        #[arg(long, value_name = "TEMPLATE")]
        commit_url: Option<String>,
    },
}

/// What run and sweep share.
#[derive(Args, Debug, Clone)]
pub struct PlanArgs {
    /// Engines, comma-separated, or `all` (every available engine but `reference`). An entry may
    /// carry settings after colons, `bvh4:simd=off`, to run variants of one engine side by side.
    #[arg(long)]
    pub engines: String,
    /// SPD programs, comma-separated, or `standard` (the seven of the SPD tables).
    #[arg(long)]
    pub scenes: String,
    /// Engine settings `engine.key=value` (repeatable).
    #[arg(long = "set", value_name = "ENGINE.KEY=VALUE")]
    pub set: Vec<String>,
    /// Repeats of each run (min, median, max are reported).
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,
    /// Rounds each run's repeats and pairs are spread over (default 3, never more than
    /// --repeat): every round runs each job once, in a process of its own, so a run's samples
    /// come from several processes minutes apart, and its intervals (and `compare`) take the
    /// round as the unit. Two processes of one binary differ by several percent in speed against
    /// Embree, which one process's samples cannot show. `sweep` runs each job in one process.
    #[arg(long, value_name = "R")]
    pub rounds: Option<u32>,
    /// Further rounds, one at a time, for the jobs whose ratio to Embree (or speed-up over one
    /// thread) is not yet known to ±--target-ci: up to M rounds in all (default 9; M = --rounds
    /// turns it off). A round beyond --rounds adds a repeat and a round's share of pairs to the
    /// job, so a busy machine's run takes more repeats than --repeat where it needs them, and a
    /// quiet one's stops at --rounds. Only jobs timed in pairs (--paired, --paired-threads) have
    /// a figure to judge.
    #[arg(long, value_name = "M")]
    pub max_rounds: Option<u32>,
    /// The half-width (percent) of the 95 % interval over rounds a job's figure must reach before
    /// its rounds stop (default 2: a third of a change `compare` flags by default, 5 %, after the
    /// two sides' intervals combine).
    #[arg(long, value_name = "PCT")]
    pub target_ci: Option<f64>,
    /// Threads: a list of counts and/or `all`, e.g. `1,all` (a count above the available
    /// parallelism is refused).
    #[arg(long, default_value = "1")]
    pub threads: String,
    /// Image size in pixels (rays go through the (size+1)² pixel corners).
    #[arg(long, default_value_t = 512, allow_hyphen_values = true)]
    pub size: u32,
    /// Skip the cross-check against Embree.
    #[arg(long)]
    pub no_check: bool,
    /// In every run of an engine other than Embree, also time at least N back-to-back pairs of the
    /// engine and Embree, shared out over the rounds (alternating which goes first; fast traces
    /// get more, until the run's pairs span two seconds over its rounds, at most 8 times each
    /// round's share); `report`
    /// shows their ratio and `compare` judges on it: load on the machine moves it far less than
    /// the ratio of two separate runs. 0 turns pairs off (and with --no-check, Embree is not
    /// built at all).
    #[arg(long, default_value_t = 5)]
    pub paired: u32,
    /// In every run at more than one thread, also time at least N back-to-back pairs (shared out
    /// over the rounds; more for fast traces, as --paired takes them) of the same trace at
    /// one thread and at the run's threads in one process (alternating which goes first), and
    /// record the speed-up over one thread per pair (`thread_scaling`: median and range);
    /// `report` shows it. Runs at one thread ignore it.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub paired_threads: u32,
    /// A run still going after this many seconds is stopped and recorded as failed.
    #[arg(long)]
    pub max_seconds: Option<f64>,
    /// A run whose resident memory passes this (bytes; K, M, G, KiB, MiB, GiB suffixes) is stopped
    /// and recorded as failed.
    #[arg(long)]
    pub max_memory: Option<String>,
    /// Skip runs the results directory already holds.
    #[arg(long)]
    pub resume: bool,
    /// The results directory (results.jsonl, env.json; created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Run only the K-th of N deterministic slices of the plan (a scene's Embree run stays with the
    /// engines compared with it; a sweep's scene stays whole); `rtbench merge` joins the N results
    /// directories. For cluster job arrays (scripts/slurm/).
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
}

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    #[command(flatten)]
    pub plan: PlanArgs,
    /// Size factors: `4`, `4,5,6` or `4..8` (default: each program's standard SF).
    #[arg(long)]
    pub sf: Option<String>,
    /// Tessellated scenes (SPD `-t`) at resolution RES.
    #[arg(long, num_args = 0..=1, default_missing_value = "3", value_name = "RES")]
    pub tessellate: Option<u32>,
}

#[derive(Args, Debug, Clone)]
pub struct SweepArgs {
    #[command(flatten)]
    pub plan: PlanArgs,
    /// First size factor of every scene.
    #[arg(long, default_value_t = 1)]
    pub sf_start: u32,
    /// Last size factor tried.
    #[arg(long, default_value_t = 64)]
    pub sf_max: u32,
}

#[derive(Args, Debug, Clone)]
pub struct ReportArgs {
    /// A results directory written by run, sweep, merge or nightly --out.
    pub dir: PathBuf,
    /// Formats, comma-separated: md, csv, json, svg, png, html (default: all).
    #[arg(long, default_value = "md,csv,json,svg,png,html")]
    pub format: String,
}

#[derive(Args, Debug, Clone)]
pub struct CompareArgs {
    /// The baseline results directory.
    pub a: PathBuf,
    /// The results directory judged against it.
    pub b: PathBuf,
    /// Slowdown (percent of the ratio to Embree) below which a change is noise.
    #[arg(long, default_value_t = 5.0)]
    pub threshold: f64,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug, Clone)]
pub struct RunOneArgs {
    #[command(flatten)]
    pub scene: SceneFlag,
    /// The engine (see `rtbench engines`), e.g. `bvh8`, `embree`, `plugin:PATH`.
    #[arg(long)]
    pub engine: String,
    /// Engine settings, `key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Threads: a count, or all the machine runs at once (default 1; more is refused with exit 2).
    #[arg(long, default_value = "1", value_parser = crate::measure::threads::parse_threads)]
    pub threads: crate::measure::threads::Threads,
    /// Repeats of the run (min, median, max are reported).
    #[arg(long, default_value_t = 3)]
    pub repeat: u32,
    /// Image size in pixels (rays go through the (size+1)² pixel corners).
    #[arg(long, default_value_t = 512)]
    pub size: u32,
    /// Skip the cross-check against Embree.
    #[arg(long)]
    pub no_check: bool,
    /// Also time at least N back-to-back pairs of this engine and Embree in this process
    /// (alternating which goes first; more, until they span two seconds, for fast traces) and
    /// record their trace-CPU-time ratios: the low-noise yardstick.
    #[arg(long, default_value_t = 0)]
    pub paired: u32,
    /// With `--threads` above 1, also time at least N back-to-back pairs of the trace at one thread and
    /// at `--threads` (alternating which goes first) and record the speed-up of each pair.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub paired_threads: u32,
    /// Exactly N pairs, however fast the trace: the nightly's rounds are its spread in time, and it
    /// takes each round's median over a fixed number of pairs.
    #[arg(long, hide = true)]
    pub pairs_exact: bool,
    /// Fast traces' pairs go on until they span this many seconds: `run` gives each of its
    /// rounds a share of two seconds.
    #[arg(long, hide = true, default_value_t = crate::measure::repeat::PAIR_SPAN_S)]
    pub pair_span: f64,
}

#[derive(Args, Debug, Clone)]
pub struct CountOneArgs {
    #[command(flatten)]
    pub scene: SceneFlag,
    #[arg(long)]
    pub engine: String,
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    #[arg(long, default_value_t = 32)]
    pub size: u32,
}

#[derive(Args, Debug, Clone)]
pub struct ReproduceArgs {
    /// A table id (see `rtbench reproduce list`), or `list`.
    pub id: String,
    /// A scaled-down run for nightly jobs.
    #[arg(long)]
    pub quick: bool,
    /// Output folder (DIR/<id>.md, DIR/<id>.json).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Keep the steps earlier runs of this id finished in DIR/.partial/<id>/ (nakamaru-3.2, -3.3,
    /// -4.1, -4.2, -fig4.4 and the yamauchi-* ids save them) and measure only the rest; without
    /// it they are removed first.
    #[arg(long)]
    pub resume: bool,
    /// Engines, comma-separated (default: every available engine but `reference`).
    #[arg(long)]
    pub engines: Option<String>,
    /// nakamaru-3.2: the largest size factor to run, `N` for every scene, `balls=6,tree=14`, or
    /// a range `tree=17..18` (the full ranges take long).
    #[arg(long)]
    pub max_sf: Option<String>,
    /// nakamaru-3.2: cost of a page fault and of a seek in ms for an extra modelled disk
    /// (beside the HDD-like 8 ms and the SSD-like 0.1 ms).
    #[arg(long)]
    pub fault_ms: Option<f64>,
    /// Threads: a count, or all the machine runs at once (default 1; more is refused with exit 2).
    #[arg(long, value_parser = crate::measure::threads::parse_threads)]
    pub threads: Option<crate::measure::threads::Threads>,
    /// yamauchi-* only: image size of 003's pass (default 512, 128 with --quick).
    #[arg(long)]
    pub size: Option<u32>,
    /// yamauchi-* only: the largest PE count simulated (default 1024).
    #[arg(long)]
    pub max_pes: Option<u32>,
    /// yamauchi-* only: SPD scenes, comma-separated (standard SFs).
    #[arg(long)]
    pub scenes: Option<String>,
    /// With `list`: the paper→code map as Markdown (the README's copy is checked against it).
    #[arg(long, conflicts_with = "json")]
    pub markdown: bool,
    /// A table's option `key=value` (repeatable; `reproduce list --json` lists each table's keys).
    /// The flags above are the same keys by their own names.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
}

#[derive(Subcommand, Debug)]
pub enum SceneCommand {
    /// The SPD programs and the room, their standard size factors and object counts; mesh files
    /// (OBJ, PLY, glTF) are accepted wherever a program name is.
    #[command(after_help = "Examples:\n  rtbench scene list\n  rtbench scene list --json")]
    List {
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
    /// Write a scene as NFF, as the SPD C program prints it.
    #[command(
        after_help = "Examples:\n  rtbench scene gen balls --sf 2                          # NFF on stdout, as SPD's balls -s 2 -r 1\n  rtbench scene gen teapot --tessellate -o teapot12.nff"
    )]
    Gen {
        #[command(flatten)]
        scene: SceneArg,
        /// Output file (written atomically); stdout when absent.
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// Refuse a scene whose NFF would pass this many bytes (estimated before writing, and
        /// held while writing): 1234, 512M, 8GiB …
        #[arg(long, value_name = "BYTES", default_value = "4GiB")]
        max_bytes: String,
    },
    /// Write a scene store for the breadth-first engine (bounding-box and geometry files,
    /// header.json), streaming from the generator without holding the scene.
    #[command(
        after_help = "Examples:\n  rtbench scene store mount --sf 10 -o mount10/\n  rtbench scene store mount --sf 12 --layout basic --compress gzip -o m12/"
    )]
    Store {
        #[command(flatten)]
        scene: SceneArg,
        /// Directory to create (must not exist, or be empty); written under a temporary name and
        /// renamed when complete.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// `split` (bbox.bin + geometry.bin, seed 000 Ch.4 "S") or `basic` (one objects.bin of
        /// (box, object) records, Ch.3); the breadth-first engine's `layout` must match.
        #[arg(long, default_value = "split")]
        layout: String,
        /// `none`, `gzip` / `gzip:LEVEL` (1-9, default 6 as gzip's): objects.bin.gz, or `zstd` /
        /// `zstd:LEVEL` (1-19, default 3): objects.bin.zst, read through the codec (seed 000
        /// Table 3.3 used gzip). `--layout split` takes zstd only: bbox.bin.zst and
        /// geometry.bin.zst as independently compressed 128 KiB blocks with an index
        /// (bbox.bin.idx, geometry.bin.idx), so that seeks decompress only the block they land in.
        #[arg(long, default_value = "none")]
        compress: String,
        /// Also build the bounding-box hierarchy (bbox-K.bin, hierarchy.json; seed 000 §4.2.2
        /// "B") with the thesis's constants for the scene (`--layout split` only).
        #[arg(long)]
        hierarchy: bool,
        /// Write in segments of N objects, each made durable with a checkpoint
        /// (`segments.json`; compressed: one gzip member, zstd frame or zstd block ends per segment), in place: a store too
        /// large to write in one sitting (seed 000 Table 4.3). Not with --hierarchy.
        #[arg(long, value_name = "N")]
        segment: Option<u64>,
        /// Go on with the store being written in the directory (with --segment).
        #[arg(long, requires = "segment")]
        resume: bool,
        /// Stop at the first checkpoint after this many seconds (with --segment).
        #[arg(long, requires = "segment", value_name = "S")]
        max_seconds: Option<f64>,
        /// Refuse a scene whose records (uncompressed) would pass this many bytes, estimated
        /// before writing and held while writing: 1234, 512M, 8GiB …
        #[arg(long, value_name = "BYTES", default_value = "16GiB")]
        max_bytes: String,
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
    /// Count a scene's primitives by streaming it.
    #[command(
        after_help = "Examples:\n  rtbench scene stats balls --sf 4 --tessellate --json\n  rtbench scene stats rings --sf 36 --view data/views/rings368m.json"
    )]
    Stats {
        #[command(flatten)]
        scene: SceneArg,
        /// Also count the objects whose box reaches into this view's frustum (a view file such
        /// as data/views/rings368m.json; 512×512 eye rays), in place of the scene's own camera.
        #[arg(long, value_name = "FILE")]
        view: Option<PathBuf>,
        /// Print one JSON document on stdout (progress and logs stay on stderr).
        #[arg(long)]
        json: bool,
    },
}

/// `<program|FILE.nff> [--sf N] [--tessellate [RES]] [--hash original|jenkins]`
#[derive(Args, Debug, Clone)]
pub struct SceneArg {
    /// An SPD program (balls, gears, mount, rings, teapot, tetra, tree, lattice, shells, jacks,
    /// sombrero) or an NFF file.
    pub scene: String,
    #[command(flatten)]
    pub opts: SceneOpts,
}

#[derive(Args, Debug, Clone)]
pub struct SceneOpts {
    /// Size factor (default: the program's standard one).
    #[arg(long, allow_hyphen_values = true)]
    pub sf: Option<u32>,
    /// Tessellated output (SPD `-t`), at resolution RES (default 3).
    #[arg(long, num_args = 0..=1, default_missing_value = "3", value_name = "RES")]
    pub tessellate: Option<u32>,
    /// mount's hash function.
    #[arg(long, value_parser = parse_hash)]
    pub hash: Option<MountHash>,
    /// Load a generated scene even when its estimated memory passes what this machine has
    /// available (render, check, tree-stats refuse it otherwise).
    #[arg(long)]
    pub force: bool,
}

// Here rather than in source.rs, so that nothing below the command line imports cli.rs.
impl crate::source::Source {
    /// The scene of a command's `<scene> [--sf N] [--tessellate [RES]] [--hash …]` arguments.
    pub fn from_args(scene: &str, o: &SceneOpts) -> crate::error::Result<Self> {
        Self::resolve(scene, o.sf, o.tessellate, o.hash)
    }
}

fn parse_hash(s: &str) -> Result<MountHash, String> {
    s.parse()
}

/// `--scene <program|FILE.nff> [--sf N] …` for render and check.
#[derive(Args, Debug, Clone)]
pub struct SceneFlag {
    /// An SPD program (balls, gears, mount, …), an NFF, OBJ, PLY or glTF file, or a scene store folder.
    #[arg(long)]
    pub scene: String,
    #[command(flatten)]
    pub opts: SceneOpts,
}

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneFlag,
    /// The engine (see `rtbench engines`), e.g. `bvh8`, `embree`, `plugin:PATH`.
    #[arg(long)]
    pub engine: String,
    /// Engine settings, `key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Image size in pixels (rays go through the (size+1)² pixel corners).
    #[arg(long, default_value_t = 512, allow_hyphen_values = true)]
    pub size: u32,
    /// Threads: a count, or all the machine runs at once (default 1; more is refused with exit 2).
    #[arg(long, default_value = "1", value_parser = crate::measure::threads::parse_threads)]
    pub threads: crate::measure::threads::Threads,
    /// Also write the image as a PNG file.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
    /// Pixel corners whose ray trees are traced to the end before the next chunk starts (in-memory
    /// engines; 0: whole generations at once). Bounds the wavefront's memory; changes no answer.
    #[arg(long, value_name = "CORNERS", default_value_t = crate::workload::trace::DEFAULT_CHUNK)]
    pub chunk: usize,
    /// Trace only the K-th of N tile sets (bands of pixel-corner rows) of a scene store's image,
    /// into --out DIR; `rtbench merge` joins the N tiles (scripts/slurm/).
    #[arg(long, value_name = "K/N", requires = "out")]
    pub tile: Option<String>,
    /// The tile's directory (with --tile).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Args, Debug, Clone)]
pub struct MergeArgs {
    /// The shards' results directories (every K of one K/N, once each).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// The merged results set (a new or empty directory).
    #[arg(long)]
    pub out: PathBuf,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug, Clone)]
pub struct PlanCmdArgs {
    /// How many shards the plan would be split into, the N of `--shard K/N` (default: one per
    /// group); before or after the subcommand.
    #[arg(long, global = true, value_name = "N")]
    pub shards: Option<u32>,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long, global = true)]
    pub json: bool,
    #[command(subcommand)]
    pub what: PlanWhat,
}

#[derive(Subcommand, Debug, Clone)]
pub enum PlanWhat {
    /// The plan of `rtbench run` with these arguments.
    Run(RunArgs),
    /// The plan of `rtbench sweep` with these arguments.
    Sweep(SweepArgs),
    /// The plan of `rtbench nightly` with this suite.
    Nightly(NightlyArgs),
}

#[derive(Args, Debug, Clone)]
pub struct TreeStatsArgs {
    #[command(flatten)]
    pub scene: SceneFlag,
    /// Branching factor: 2 to 16, even (001's N); a power of two with wide=direct and a SAH builder.
    #[arg(long, default_value_t = 4, allow_hyphen_values = true)]
    pub width: usize,
    /// BVH settings, `key=value` (builder, wide, leaf, bins, split_leaves; see `rtbench engines`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug, Clone)]
pub struct CheckArgs {
    /// An SPD program or an NFF file (required unless --suite is given).
    #[arg(long)]
    pub scene: Option<String>,
    #[command(flatten)]
    pub opts: SceneOpts,
    /// The engine to check; with --suite, engines comma-separated (default: every available one).
    #[arg(long)]
    pub engine: Option<String>,
    /// Engine settings, `key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The engine to check against: embree (default) or reference.
    #[arg(long)]
    pub against: Option<String>,
    /// Image size (default 512; with --suite tessellation, 128).
    #[arg(long)]
    pub size: Option<u32>,
    /// Minimum hit agreement (fraction of rays) for the check to pass (default 0.9999).
    #[arg(long)]
    pub threshold: Option<f64>,
    /// Threads: a count, or all the machine runs at once (default 1; more is refused with exit 2).
    #[arg(long, default_value = "1", value_parser = crate::measure::threads::parse_threads)]
    pub threads: crate::measure::threads::Threads,
    /// Print one JSON document on stdout (progress and logs stay on stderr).
    #[arg(long)]
    pub json: bool,
    /// Run a suite instead of one scene: `hard` (hard cases, acne, speed against error) or
    /// `tessellation` (curved against --tessellate 1…8).
    #[arg(long)]
    pub suite: Option<String>,
    /// Folder for the suite's report (SUITE.md, SUITE.json, plots/).
    #[arg(long)]
    pub out: Option<PathBuf>,
}
