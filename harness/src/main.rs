//! `rtbench`: the command-line harness. `rtbench --help` lists the commands; docs/ explains them.

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
mod measure;
mod nightly;
mod output;
mod reproduce;
mod runs;
mod select;
mod shard;
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
    // `rtbench env` shows the variables as they are, malformed ones too.
    if !matches!(cli.command, Command::Env { .. }) {
        measure::vars::load()?;
    }
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
        Command::Env { json } => commands::env::list(json),
        Command::Render(a) => commands::render::run(&a),
        Command::Check(a) => commands::check::run(&a),
        Command::TreeStats(a) => commands::tree_stats::run(&a),
        Command::Run(a) => commands::runs::run(&a),
        Command::Sweep(a) => commands::runs::sweep(&a),
        Command::RunOne(a) => commands::runs::run_one_cmd(&a),
        Command::CountOne(a) => commands::nightly::count_one(&a),
        Command::Report(a) => commands::runs::report(&a),
        Command::Compare(a) => commands::runs::compare(&a),
        Command::Nightly(a) => commands::nightly::run(&a),
        Command::History(c) => commands::history::run(&c),
        Command::Merge(a) => commands::merge::run(&a),
        Command::Plan(a) => commands::plan::run(&a),
        Command::Reproduce(a) if a.id == "list" => reproduce::list(a.json, a.markdown),
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

/// clap's whole message on one line: the problem, the arguments it names (a missing argument is
/// on the lines after "were not provided:") and its tip ("a similar argument exists"), without
/// the usage and "For more information" lines that follow.
fn one_line(text: &str) -> String {
    let mut parts: Vec<String> = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        if line.is_empty() {
            continue;
        }
        let line = line.trim_start_matches("error: ");
        match parts.last_mut() {
            Some(last) if last.ends_with(':') => {
                last.push(' ');
                last.push_str(line);
            }
            _ => parts.push(line.to_string()),
        }
    }
    if parts.is_empty() {
        return "bad usage".to_string();
    }
    let mut out = parts.remove(0);
    for p in parts {
        if p.starts_with("tip:") {
            out.push_str(&format!(" ({p})"));
        } else {
            out.push_str(&format!(", {p}"));
        }
    }
    out
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
            eprintln!("rtbench: {}", one_line(&e.render().to_string()));
            std::process::exit(2);
        }
    };
    if let Err(e) = run(cli).and_then(|()| output::stdout_status()) {
        eprintln!("rtbench: {e}");
        std::process::exit(e.exit_code());
    }
}

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn a_usage_error_keeps_the_argument_and_the_tip() {
        let missing = "error: the following required arguments were not provided:\n  --scenes <SCENES>\n\nUsage: rtbench run --engines <ENGINES> --scenes <SCENES> --out <OUT>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(missing),
            "the following required arguments were not provided: --scenes <SCENES>"
        );
        let two = "error: the following required arguments were not provided:\n  --scenes <SCENES>\n  --out <OUT>\n\nUsage: x\n";
        assert_eq!(
            one_line(two),
            "the following required arguments were not provided: --scenes <SCENES>, --out <OUT>"
        );
        let tip = "error: unexpected argument '--shards' found\n\n  tip: a similar argument exists: '--shard'\n\nUsage: rtbench run --shard <K/N>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(tip),
            "unexpected argument '--shards' found (tip: a similar argument exists: '--shard')"
        );
    }
}
