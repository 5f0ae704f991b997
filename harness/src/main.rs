//! `rtbench`: the command-line harness. See ../shared/CLI.md for the contract.

// Every `print!`/`println!` of this crate goes through these: a failed write to stdout (`> /dev/full`)
// is kept and reported once at the end (exit 2) instead of std's panic. Defined before the
// modules so that their textual scope covers them all.
macro_rules! println {
    () => {
        $crate::output::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

macro_rules! print {
    ($($arg:tt)*) => {
        $crate::output::write_stdout(format_args!($($arg)*))
    };
}

mod cli;
mod commands;
mod error;
mod history;
mod nightly;
mod output;
mod reproduce;
mod runs;
mod select;
mod source;
mod suite;
mod workload;

#[cfg(test)]
mod fuzz;

use clap::Parser;
use cli::{Cli, Command, SceneCommand};
use error::Result;
use source::Source;

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Scene(SceneCommand::List { json }) => commands::scene::list(json),
        Command::Scene(SceneCommand::Gen {
            scene,
            output,
            max_bytes,
        }) => commands::scene::gen(
            &Source::from_args(&scene.scene, &scene.opts)?,
            output.as_deref(),
            commands::scene::max_bytes(&max_bytes)?,
        ),
        Command::Scene(SceneCommand::Store {
            scene,
            output,
            layout,
            compress,
            hierarchy,
            segment,
            resume,
            max_seconds,
            max_bytes,
            json,
        }) => match segment {
            Some(segment) if hierarchy => Err(error::input(format!(
                "--segment {segment} --hierarchy: build the hierarchy once the store is finished (render with --set hierarchy=on)"
            ))),
            Some(segment) => commands::store_segments::store(
                &Source::from_args(&scene.scene, &scene.opts)?,
                &output,
                &commands::store_segments::SegmentArgs {
                    layout: &layout,
                    compress: &compress,
                    segment,
                    resume,
                    max_seconds,
                    max_bytes: commands::scene::max_bytes(&max_bytes)?,
                    as_json: json,
                },
            ),
            None => commands::scene::store(
                &Source::from_args(&scene.scene, &scene.opts)?,
                &output,
                &layout,
                &compress,
                hierarchy,
                commands::scene::max_bytes(&max_bytes)?,
                json,
            ),
        },
        Command::Scene(SceneCommand::Stats {
            scene,
            view: Some(view),
            json,
        }) => commands::scene::view_stats(
            &Source::from_args(&scene.scene, &scene.opts)?,
            &view,
            json,
        ),
        Command::Scene(SceneCommand::Stats {
            scene,
            view: None,
            json,
        }) => commands::scene::stats(&Source::from_args(&scene.scene, &scene.opts)?, json),
        Command::Engines { json } => commands::engines::list(json),
        Command::Render(a) => commands::render::run(&a),
        Command::Check(a) => commands::check::run(&a),
        Command::TreeStats(a) => commands::tree_stats::run(&a),
        Command::Run(a) => commands::runs::run(&a),
        Command::Sweep(a) => commands::runs::sweep(&a),
        Command::RunOne(a) => commands::runs::run_one_cmd(&a),
        Command::Report(a) => commands::runs::report(&a),
        Command::Compare(a) => commands::runs::compare(&a),
        Command::Nightly(a) => nightly::run(&a),
        Command::History(c) => nightly::history_cmd(&c),
        Command::Merge(a) => commands::merge::run(&a),
        Command::Plan(a) => commands::plan::run(&a),
        Command::Reproduce(a) if a.id == "list" => reproduce::list(a.json),
        Command::Reproduce(a) => {
            let out = a
                .out
                .as_deref()
                .ok_or_else(|| error::input("reproduce: --out DIR is required"))?;
            reproduce::run(&a.id, a.quick, out, a.resume, reproduce_pairs(&a)?, a.json)
        }
    }
}

/// The reproduce flags as a table's option pairs: each flag is the key of its own name, then `--set`.
fn reproduce_pairs(a: &cli::ReproduceArgs) -> Result<Vec<(String, String)>> {
    let mut pairs = Vec::new();
    let mut flag = |key: &str, value: Option<String>| {
        if let Some(v) = value {
            pairs.push((key.to_string(), v));
        }
    };
    flag("engines", a.engines.clone());
    flag("threads", a.threads.map(|t| t.to_string()));
    flag("max-sf", a.max_sf.clone());
    flag("fault-ms", a.fault_ms.map(|t| t.to_string()));
    flag("size", a.size.map(|t| t.to_string()));
    flag("max-pes", a.max_pes.map(|t| t.to_string()));
    flag("scenes", a.scenes.clone());
    pairs.extend(reproduce::parse_set(&a.id, &a.set)?);
    Ok(pairs)
}

fn main() {
    // Rust ignores SIGPIPE, so `rtbench … | head` would panic in println!. Restore the default:
    // the process ends quietly when its reader goes away, as other Unix tools do.
    // SAFETY: signal() with SIG_DFL touches no Rust state; it runs before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let _ = e.print();
                std::process::exit(
                    if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                        2
                    } else {
                        0
                    },
                );
            }
            // One line: clap's first line names the problem and the argument.
            let text = e.render().to_string();
            let first = text
                .lines()
                .next()
                .unwrap_or("bad usage")
                .trim_start_matches("error: ");
            eprintln!("rtbench: {first}");
            std::process::exit(2);
        }
    };
    if let Err(e) = run(cli).and_then(|()| output::stdout_status()) {
        eprintln!("rtbench: {e}");
        std::process::exit(e.exit_code());
    }
}
