//! The command line (../shared/CLI.md). Names here are a contract: extend, never rename.

use clap::{Args, Parser, Subcommand};
use rtbench_scenes::spd::MountHash;
use std::path::PathBuf;

#[derive(Parser, Debug)]
#[command(
    name = "rtbench",
    version,
    about = "Benchmark and reproducibility harness for ray-tracing acceleration structures"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Generate SPD scenes, show their statistics.
    #[command(subcommand)]
    Scene(SceneCommand),
    /// List the engines and whether each can run here.
    Engines {
        #[arg(long)]
        json: bool,
    },
    /// Trace the SPD workload for one scene with one engine.
    Render(RenderArgs),
    /// Cross-check an engine's hits against Embree or the reference engine on the same rays.
    Check(CheckArgs),
    /// Remeasure a published table: `reproduce list`, `reproduce <id> --out DIR`.
    Reproduce(ReproduceArgs),
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
    /// Engines, comma-separated (default: every available engine but `reference`).
    #[arg(long)]
    pub engines: Option<String>,
    #[arg(long)]
    pub threads: Option<usize>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Subcommand, Debug)]
pub enum SceneCommand {
    /// The SPD programs, their standard size factors and object counts.
    List {
        #[arg(long)]
        json: bool,
    },
    /// Write a scene as NFF, as the SPD C program prints it.
    Gen {
        #[command(flatten)]
        scene: SceneArg,
        /// Output file (written atomically); stdout when absent.
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
    },
    /// Count a scene's primitives by streaming it.
    Stats {
        #[command(flatten)]
        scene: SceneArg,
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
}

fn parse_hash(s: &str) -> Result<MountHash, String> {
    s.parse()
}

/// `--scene <program|FILE.nff> [--sf N] …` for render and check.
#[derive(Args, Debug, Clone)]
pub struct SceneFlag {
    #[arg(long)]
    pub scene: String,
    #[command(flatten)]
    pub opts: SceneOpts,
}

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneFlag,
    #[arg(long)]
    pub engine: String,
    /// Engine settings, `key=value` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Image size in pixels (rays go through the (size+1)² pixel corners).
    #[arg(long, default_value_t = 512, allow_hyphen_values = true)]
    pub size: u32,
    /// Threads for tracing (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    #[arg(long)]
    pub png: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug, Clone)]
pub struct CheckArgs {
    #[command(flatten)]
    pub scene: SceneFlag,
    #[arg(long)]
    pub engine: String,
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The engine to check against: embree or reference.
    #[arg(long, default_value = "embree")]
    pub against: String,
    #[arg(long, default_value_t = 512)]
    pub size: u32,
    /// Minimum hit agreement (fraction of rays) for the check to pass.
    #[arg(long, default_value_t = 0.9999)]
    pub threshold: f64,
    #[arg(long)]
    pub threads: Option<usize>,
    #[arg(long)]
    pub json: bool,
}
