//! `write_report` on synthetic results directories.

mod common;

use common::{failed, run, write_set, TempDir};
use rtbench_reports::{write_report, Format, ReportError, RunRecord};

/// balls at SF 3, 4, 5 with embree, bvh2 (2.5× Embree's trace time) and grid (0.8×); teapot at SF 3
/// with bvh2 only (no yardstick); one failed run.
fn sample_set(dir: &std::path::Path) {
    let mut records = Vec::new();
    for sf in 3..=5 {
        let t = 0.1 * 3f64.powi(sf as i32 - 3);
        records.push(run("embree", "balls", sf, t));
        records.push(run("bvh2", "balls", sf, 2.5 * t));
        records.push(run("grid", "balls", sf, 0.8 * t));
    }
    records.push(run("bvh2", "teapot", 3, 0.2));
    records.push(failed("grid", "teapot", 3, "time limit 600 s passed"));
    write_set(dir, &records);
}

fn read(path: &std::path::Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The cells of the Markdown table row for (scene, engine).
fn md_row(md: &str, scene: &str, engine: &str) -> Vec<String> {
    md.lines()
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect::<Vec<_>>()
        })
        .find(|cells| cells.len() == 12 && cells[0] == scene && cells[1] == engine)
        .unwrap_or_else(|| panic!("no row for {scene} / {engine} in:\n{md}"))
}

#[test]
fn markdown_table_has_ratio_to_embree_and_failures() {
    let dir = TempDir::new("md");
    sample_set(dir.path());
    let summary = write_report(dir.path(), &Format::ALL).unwrap();
    assert_eq!(summary.runs, 11);
    assert_eq!(summary.rows.len(), 10);
    assert_eq!(summary.failures.len(), 1);

    let md = read(&dir.path().join("report.md"));
    assert!(
        md.contains("Synthetic CPU 9000"),
        "environment header:\n{md}"
    );
    assert!(md.contains("## 1 thread"));
    // Columns: scene, engine, build, trace, Mrays/s, × Embree [95 % CI] (n), paired × Embree,
    // structure MB, B/prim, peak RSS MB, agreement, PSNR.
    let bvh2 = md_row(&md, "balls4", "bvh2");
    assert!(
        bvh2[5].starts_with("2.50 [2.4") && bvh2[5].ends_with("(6)"),
        "{}",
        bvh2[5]
    );
    assert_eq!(bvh2[6], "–", "no paired ratios in this set");
    assert_eq!(bvh2[3], "0.750 (0.743–0.758)");
    assert_eq!(bvh2[8], "2000.0", "structure bytes per primitive");
    assert_eq!(bvh2[10], "99.998%");
    assert_eq!(bvh2[11], "48.3");
    let grid = md_row(&md, "balls5", "grid");
    assert!(grid[5].starts_with("0.80 ["), "{}", grid[5]);
    assert_eq!(grid[10], "100%");
    assert_eq!(grid[11], "∞");
    let embree = md_row(&md, "balls3", "embree");
    assert_eq!(embree[5], "1.00");
    assert_eq!(embree[10], "–", "Embree has no check against itself");
    // No Embree run on teapot3: no ratio.
    assert_eq!(md_row(&md, "teapot3", "bvh2")[5], "–");
    // Embree first within a scene.
    let first = md.lines().find(|l| l.starts_with("| balls3 |")).unwrap();
    assert!(first.starts_with("| balls3 | embree |"), "{first}");
    assert!(md.contains("## Failed runs"));
    assert!(
        md.contains("`grid/teapot3@1`: failed: time limit 600 s passed"),
        "{md}"
    );
    assert!(md.contains("![plots/time-vs-sf-balls.svg](plots/time-vs-sf-balls.svg)"));
}

#[test]
fn csv_json_and_html_are_written() {
    let dir = TempDir::new("files");
    sample_set(dir.path());
    let summary = write_report(dir.path(), &Format::ALL).unwrap();
    for f in ["report.md", "results.csv", "summary.json", "report.html"] {
        assert!(
            summary.files.iter().any(|x| x == f),
            "{f} not in {:?}",
            summary.files
        );
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }

    let csv = read(&dir.path().join("results.csv"));
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 12, "header and one row per run");
    let header: Vec<&str> = lines[0].split(',').collect();
    let ratio_col = header.iter().position(|h| *h == "ratio_to_embree").unwrap();
    assert!(header.contains(&"counter.nodes_visited"));
    let bvh2 = lines
        .iter()
        .find(|l| l.starts_with("bvh2/balls4@1,"))
        .unwrap();
    let ratio: f64 = bvh2.split(',').nth(ratio_col).unwrap().parse().unwrap();
    assert!((ratio - 2.5).abs() < 1e-9, "{ratio}");
    assert!(lines
        .iter()
        .any(|l| l.starts_with("grid/teapot3@1,failed,time limit 600 s passed,")));

    let json: serde_json::Value =
        serde_json::from_str(&read(&dir.path().join("summary.json"))).unwrap();
    assert_eq!(json["runs"], 11);
    assert_eq!(json["rows"].as_array().unwrap().len(), 10);
    assert_eq!(json["failures"][0]["reason"], "time limit 600 s passed");
    assert_eq!(json["environment"]["git_commit"], "abc1234");

    let html = read(&dir.path().join("report.html"));
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(
        html.contains("<td class=\"n\">2.50 [2.4"),
        "ratio cell in the HTML table"
    );
    assert_eq!(
        html.matches("<svg").count(),
        summary.files.iter().filter(|f| f.ends_with(".svg")).count()
    );
    assert!(!html.contains("<?xml"));
}

#[test]
fn plots_are_written_and_decode() {
    let dir = TempDir::new("plots");
    sample_set(dir.path());
    let summary = write_report(dir.path(), &Format::ALL).unwrap();
    let mut stems: Vec<&str> = summary
        .files
        .iter()
        .filter_map(|f| f.strip_prefix("plots/")?.strip_suffix(".svg"))
        .collect();
    stems.sort();
    assert_eq!(
        stems,
        [
            "memory-vs-sf-balls",
            "mrays-balls3",
            "mrays-balls4",
            "mrays-balls5",
            "mrays-teapot3",
            "ratio-balls3",
            "ratio-balls4",
            "ratio-balls5",
            "speed-vs-error",
            "time-vs-sf-balls"
        ],
        "teapot has one SF: no time-vs-SF plot; no Embree run on teapot: no ratio plot"
    );
    for stem in stems {
        let svg = read(&dir.path().join(format!("plots/{stem}.svg")));
        assert!(
            svg.len() > 1000 && svg.contains("<svg") && svg.trim_end().ends_with("</svg>"),
            "{stem}.svg"
        );
        let png = image::open(dir.path().join(format!("plots/{stem}.png")))
            .unwrap()
            .to_rgb8();
        assert!(png.width() >= 640 && png.height() >= 400, "{stem}.png size");
        // The title band was drawn with the bundled font: dark pixels there.
        let dark_title = (0..png.width())
            .flat_map(|x| (0..40).map(move |y| (x, y)))
            .filter(|&(x, y)| png.get_pixel(x, y)[0] < 100)
            .count();
        assert!(
            dark_title > 100,
            "{stem}.png: no title text ({dark_title} dark pixels)"
        );
        // bvh2 is the first engine after Embree: the palette's blue.
        let blue = png.pixels().filter(|p| p.0 == [31, 119, 180]).count();
        assert!(blue > 20, "{stem}.png: no bvh2 colour ({blue} pixels)");
    }
    let svg = read(&dir.path().join("plots/time-vs-sf-balls.svg"));
    for label in ["embree", "bvh2", "grid", "balls: time vs SF"] {
        assert!(svg.contains(label), "time-vs-sf-balls.svg lacks {label}");
    }
}

#[test]
fn only_the_formats_asked_for() {
    let dir = TempDir::new("some");
    sample_set(dir.path());
    let summary = write_report(dir.path(), &[Format::Md, Format::Png]).unwrap();
    assert!(dir.path().join("report.md").is_file());
    assert!(dir.path().join("plots/mrays-balls4.png").is_file());
    assert!(!dir.path().join("plots/mrays-balls4.svg").exists());
    assert!(!dir.path().join("results.csv").exists());
    assert!(!dir.path().join("summary.json").exists());
    assert!(!dir.path().join("report.html").exists());
    assert!(summary
        .files
        .iter()
        .all(|f| f == "report.md" || f.ends_with(".png")));
    let md = read(&dir.path().join("report.md"));
    assert!(
        md.contains("![plots/mrays-balls4.png](plots/mrays-balls4.png)"),
        "PNG shown without SVG"
    );
    // No temp files left behind.
    for d in [dir.path().to_path_buf(), dir.path().join("plots")] {
        for e in std::fs::read_dir(d).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!name.contains(".tmp-"), "{name}");
        }
    }
}

#[test]
fn a_later_line_replaces_an_earlier_one_with_the_same_key() {
    let dir = TempDir::new("rerun");
    write_set(
        dir.path(),
        &[
            run("embree", "balls", 3, 1.0),
            failed("bvh2", "balls", 3, "killed"),
            RunRecord {
                finished_at: "2026-01-01T00:10:00Z".into(),
                ..run("bvh2", "balls", 3, 3.0)
            },
        ],
    );
    let summary = write_report(dir.path(), &[Format::Md]).unwrap();
    assert_eq!(summary.runs, 2);
    assert!(summary.failures.is_empty());
    let cell = md_row(&read(&dir.path().join("report.md")), "balls3", "bvh2")[5].clone();
    assert!(cell.starts_with("3.00 ["), "{cell}");
}

#[test]
fn errors_name_the_file() {
    let dir = TempDir::new("empty");
    let e = write_report(dir.path(), &Format::ALL).unwrap_err();
    assert!(matches!(e, ReportError::NoResults { .. }));
    assert!(e.to_string().contains("results.jsonl"), "{e}");

    std::fs::write(dir.path().join("results.jsonl"), "{\"key\": 3}\n").unwrap();
    let e = write_report(dir.path(), &Format::ALL).unwrap_err();
    assert!(e.to_string().contains("results.jsonl:1"), "{e}");

    assert_eq!(
        Format::parse_list("md, png,md").unwrap(),
        [Format::Md, Format::Png]
    );
    let e = Format::parse_list("md,pdf").unwrap_err();
    assert!(e.to_string().contains("`pdf`"), "{e}");
}

#[test]
fn empty_results_are_refused() {
    let dir = TempDir::new("none");
    std::fs::write(dir.path().join("results.jsonl"), "").unwrap();
    let e = write_report(dir.path(), &Format::ALL).unwrap_err();
    assert!(e.to_string().contains("holds no runs"), "{e}");
    assert!(!dir.path().join("report.md").exists());
}

#[test]
fn one_table_per_thread_count_and_ratios_within_it() {
    let dir = TempDir::new("threads");
    let mut records = Vec::new();
    for threads in [1, 2] {
        for sf in [3, 4] {
            let t = sf as f64 / threads as f64;
            let mut e = run("embree", "balls", sf, t);
            // bvh2 scales worse with threads: 2× Embree on one thread, 3× on two.
            let mut b = run("bvh2", "balls", sf, t * (threads + 1) as f64);
            for r in [&mut e, &mut b] {
                r.threads = threads;
                r.key = rtbench_reports::run_key(&r.engine, &r.settings, &r.scene.name, threads);
            }
            records.extend([e, b]);
        }
    }
    write_set(dir.path(), &records);
    let summary = write_report(dir.path(), &[Format::Md, Format::Svg]).unwrap();
    let md = read(&dir.path().join("report.md"));
    let one = md.find("## 1 thread\n").expect("table for 1 thread");
    let two = md.find("## 2 threads\n").expect("table for 2 threads");
    assert!(md_row(&md[one..two], "balls4", "bvh2")[5].starts_with("2.00 ["));
    assert!(md_row(&md[two..], "balls4", "bvh2")[5].starts_with("3.00 ["));
    for stem in [
        "time-vs-sf-balls-t1",
        "time-vs-sf-balls-t2",
        "mrays-balls3-t2",
    ] {
        let f = format!("plots/{stem}.svg");
        assert!(summary.files.contains(&f), "{f} not in {:?}", summary.files);
    }
}
