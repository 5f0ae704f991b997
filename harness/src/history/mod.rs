//! The nightly history: one SQLite file (rusqlite's bundled SQLite, no system library).
//!
//! - `runs`: one row per night (suite, commit, environment and its fingerprint, wall time);
//! - `metrics`: the night's value of each metric (a median ratio, a counter, an instruction count,
//!   a criterion estimate), with its kind, unit and whether it gated;
//! - `samples`: every repeat behind a metric (the ratio of each repeat, each trace time, each
//!   criterion sample), not only the median;
//! - `findings`: what the night's comparison reported.
//!
//! The schema version is `PRAGMA user_version` ([`SCHEMA`]); a newer one is refused (exit 2). The
//! journal is WAL with a busy timeout, and a night is written in one `BEGIN IMMEDIATE` transaction
//! after it was measured: two writers both land, and a crash loses at most the night in progress.

use crate::error::{input, Result};
use rusqlite::{params, Connection, OpenFlags, OptionalExtension};
use std::path::Path;

pub mod dashboard;
pub mod detect;
pub mod export;

/// The schema this rtbench writes and reads.
pub const SCHEMA: i64 = 1;
/// `PRAGMA application_id`: marks the file as an rtbench history ("rtbh").
const APP_ID: i64 = 0x7274_6268;

const CREATE: &str = "
CREATE TABLE IF NOT EXISTS runs(
    id INTEGER PRIMARY KEY,
    suite TEXT NOT NULL,
    suite_sha256 TEXT NOT NULL,
    started_at TEXT NOT NULL,
    finished_at TEXT NOT NULL,
    git_commit TEXT NOT NULL,
    git_dirty INTEGER NOT NULL,
    fingerprint TEXT NOT NULL,
    env_json TEXT NOT NULL,
    wall_s REAL NOT NULL,
    regressions INTEGER NOT NULL,
    note TEXT
);
CREATE TABLE IF NOT EXISTS metrics(
    run_id INTEGER NOT NULL REFERENCES runs(id),
    name TEXT NOT NULL,
    kind TEXT NOT NULL,
    unit TEXT NOT NULL,
    value REAL NOT NULL,
    gated INTEGER NOT NULL,
    PRIMARY KEY(run_id, name)
);
CREATE TABLE IF NOT EXISTS samples(
    run_id INTEGER NOT NULL REFERENCES runs(id),
    name TEXT NOT NULL,
    idx INTEGER NOT NULL,
    value REAL NOT NULL,
    PRIMARY KEY(run_id, name, idx)
);
CREATE TABLE IF NOT EXISTS findings(
    run_id INTEGER NOT NULL REFERENCES runs(id),
    name TEXT NOT NULL,
    verdict TEXT NOT NULL,
    baseline REAL,
    value REAL,
    change_pct REAL,
    message TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS runs_fp ON runs(fingerprint, suite, id);
CREATE INDEX IF NOT EXISTS metrics_name ON metrics(name, run_id);
";

/// Every table's columns and declared types, as [`CREATE`] makes them (`history check`).
const COLUMNS: [(&str, &[(&str, &str)]); 4] = [
    (
        "runs",
        &[
            ("id", "INTEGER"),
            ("suite", "TEXT"),
            ("suite_sha256", "TEXT"),
            ("started_at", "TEXT"),
            ("finished_at", "TEXT"),
            ("git_commit", "TEXT"),
            ("git_dirty", "INTEGER"),
            ("fingerprint", "TEXT"),
            ("env_json", "TEXT"),
            ("wall_s", "REAL"),
            ("regressions", "INTEGER"),
            ("note", "TEXT"),
        ],
    ),
    (
        "metrics",
        &[
            ("run_id", "INTEGER"),
            ("name", "TEXT"),
            ("kind", "TEXT"),
            ("unit", "TEXT"),
            ("value", "REAL"),
            ("gated", "INTEGER"),
        ],
    ),
    (
        "samples",
        &[
            ("run_id", "INTEGER"),
            ("name", "TEXT"),
            ("idx", "INTEGER"),
            ("value", "REAL"),
        ],
    ),
    (
        "findings",
        &[
            ("run_id", "INTEGER"),
            ("name", "TEXT"),
            ("verdict", "TEXT"),
            ("baseline", "REAL"),
            ("value", "REAL"),
            ("change_pct", "REAL"),
            ("message", "TEXT"),
        ],
    ),
];

/// Columns that hold numbers.
const NUMERIC: [(&str, &str); 9] = [
    ("runs", "wall_s"),
    ("runs", "git_dirty"),
    ("runs", "regressions"),
    ("metrics", "value"),
    ("metrics", "gated"),
    ("samples", "value"),
    ("findings", "baseline"),
    ("findings", "value"),
    ("findings", "change_pct"),
];

/// `file:` URI of `path` (RFC 3986 escapes), `immutable=1` when asked.
fn file_uri(path: &Path, immutable: bool) -> String {
    use std::os::unix::ffi::OsStrExt;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut uri = String::from("file:");
    for &b in abs.as_os_str().as_bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            uri.push(b as char);
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri.push_str(if immutable {
        "?mode=ro&immutable=1"
    } else {
        "?mode=ro"
    });
    uri
}

/// One metric of a night.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Metric {
    pub name: String,
    /// `counter`, `time_ratio`, `time`, `instructions`, `criterion`.
    pub kind: String,
    pub unit: String,
    pub value: f64,
    pub gated: bool,
    pub samples: Vec<f64>,
}

/// What the comparison of a night reported about one metric.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Finding {
    pub name: String,
    /// `regression`, `improvement`, `failed`, `change` (an ungated metric moved), `suspect` (a
    /// time slowdown on its first night), `ok` (a gated metric compared and unchanged: the message
    /// names what it was compared against), `gate` (a gate's state that night, named
    /// `gate/<gate>`: `baseline` holds the night's baseline nights, `value` those the gate needs).
    pub verdict: String,
    pub baseline: Option<f64>,
    pub value: Option<f64>,
    pub change_pct: Option<f64>,
    pub message: String,
}

/// A night to write.
#[derive(Clone, Debug)]
pub struct Night {
    pub suite: String,
    pub suite_sha256: String,
    pub started_at: String,
    pub finished_at: String,
    pub git_commit: String,
    pub git_dirty: bool,
    pub fingerprint: String,
    pub env_json: String,
    pub wall_s: f64,
    pub note: Option<String>,
    pub metrics: Vec<Metric>,
    pub findings: Vec<Finding>,
}

/// A night as listed.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RunRow {
    pub id: i64,
    pub suite: String,
    pub started_at: String,
    pub git_commit: String,
    pub git_dirty: bool,
    pub fingerprint: String,
    pub wall_s: f64,
    pub regressions: i64,
    pub metrics: i64,
    pub note: Option<String>,
}

pub struct History {
    conn: Connection,
    path: String,
}

fn db_err(path: &str, e: rusqlite::Error) -> crate::error::Failure {
    let msg = match &e {
        rusqlite::Error::SqliteFailure(f, m) if f.code == rusqlite::ErrorCode::NotADatabase => {
            m.clone().unwrap_or_else(|| "file is not a database".into())
        }
        _ => e.to_string(),
    };
    input(format!("{path}: {}", msg.lines().next().unwrap_or("")))
}

impl History {
    /// Opens (creating if `create`) a history, checking that it is one and that its schema is not
    /// newer than ours.
    pub fn open(path: &Path, create: bool) -> Result<History> {
        let p = path.display().to_string();
        if !create && !path.is_file() {
            return Err(input(format!("{p}: no such history file")));
        }
        let mut flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        if create {
            flags |= OpenFlags::SQLITE_OPEN_CREATE;
        }
        let conn = Connection::open_with_flags(path, flags).map_err(|e| db_err(&p, e))?;
        let e = |e| db_err(&p, e);
        conn.busy_timeout(std::time::Duration::from_secs(60))
            .map_err(e)?;
        // The first read of the header: fails here on a file that is not SQLite.
        let version: i64 = conn
            .query_row("PRAGMA user_version", [], |r| r.get(0))
            .map_err(e)?;
        let app: i64 = conn
            .query_row("PRAGMA application_id", [], |r| r.get(0))
            .map_err(e)?;
        if version > SCHEMA {
            return Err(input(format!(
                "{p}: history schema {version} is newer than this rtbench's ({SCHEMA}); use a newer rtbench"
            )));
        }
        let tables: i64 = conn
            .query_row("SELECT count(*) FROM sqlite_master", [], |r| r.get(0))
            .map_err(e)?;
        if tables > 0 && app != APP_ID {
            return Err(input(format!(
                "{p}: an SQLite file but not an rtbench history (application_id {app:#x})"
            )));
        }
        conn.pragma_update(None, "journal_mode", "WAL").map_err(e)?;
        conn.pragma_update(None, "synchronous", "NORMAL")
            .map_err(e)?;
        if version < SCHEMA {
            // Creating (or upgrading from nothing): one transaction, so a second process that
            // races us sees either no tables or all of them.
            conn.execute_batch(&format!(
                "BEGIN IMMEDIATE; {CREATE} PRAGMA application_id = {APP_ID}; PRAGMA user_version = {SCHEMA}; COMMIT;"
            ))
            .map_err(e)?;
        }
        Ok(History { conn, path: p })
    }

    /// Opens a history for reading only: nothing is written, not even a schema into an empty
    /// file, and a history in a read-only directory reads (as an immutable file when SQLite
    /// cannot make its shared-memory file beside it).
    pub fn open_read(path: &Path) -> Result<History> {
        let p = path.display().to_string();
        if !path.is_file() {
            return Err(input(format!("{p}: no such history file")));
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_ONLY
            | OpenFlags::SQLITE_OPEN_NO_MUTEX
            | OpenFlags::SQLITE_OPEN_URI;
        let header = |conn: &Connection| -> rusqlite::Result<(i64, i64, i64)> {
            conn.busy_timeout(std::time::Duration::from_secs(60))?;
            Ok((
                conn.query_row("PRAGMA user_version", [], |r| r.get(0))?,
                conn.query_row("PRAGMA application_id", [], |r| r.get(0))?,
                conn.query_row("SELECT count(*) FROM sqlite_master", [], |r| r.get(0))?,
            ))
        };
        let plain = Connection::open_with_flags(file_uri(path, false), flags)
            .and_then(|c| header(&c).map(|h| (c, h)));
        let (conn, (version, app, tables)) = match plain {
            Ok(x) => x,
            Err(first) => Connection::open_with_flags(file_uri(path, true), flags)
                .and_then(|c| header(&c).map(|h| (c, h)))
                .map_err(|_| db_err(&p, first))?,
        };
        if tables == 0 {
            return Err(input(format!("{p}: holds no history (no tables)")));
        }
        // As the writing open says it: a newer rtbench's history is named as such first.
        if version > SCHEMA {
            return Err(input(format!(
                "{p}: history schema {version} is newer than this rtbench's ({SCHEMA}); use a newer rtbench"
            )));
        }
        if app != APP_ID {
            return Err(input(format!(
                "{p}: an SQLite file but not an rtbench history (application_id {app:#x})"
            )));
        }
        if version != SCHEMA {
            return Err(input(format!(
                "{p}: history schema {version}; this rtbench reads schema {SCHEMA}"
            )));
        }
        Ok(History { conn, path: p })
    }

    /// What keeps the history from being whole, one line each (empty when whole): SQLite's
    /// integrity check, the schema version and application id, every table with exactly its
    /// columns, numbers where numbers belong, and every night holding as many metrics (measured
    /// or recorded as failed) as the other nights of the same suite file.
    pub fn problems(&self) -> Result<Vec<String>> {
        let q = |sql: &str| -> Result<i64> {
            self.conn
                .query_row(sql, [], |r| r.get(0))
                .map_err(|e| self.err(e))
        };
        let mut out = Vec::new();
        let verdict: String = self
            .conn
            .query_row("PRAGMA integrity_check", [], |r| r.get(0))
            .map_err(|e| self.err(e))?;
        if verdict != "ok" {
            out.push(format!(
                "integrity_check: {}",
                crate::output::head(&verdict, 200)
            ));
        }
        let version = q("PRAGMA user_version")?;
        if version != SCHEMA {
            out.push(format!("schema version {version}, expected {SCHEMA}"));
        }
        let app = q("PRAGMA application_id")?;
        if app != APP_ID {
            out.push(format!("application_id {app:#x}, expected {APP_ID:#x}"));
        }
        let mut tables_ok = true;
        for (table, want) in COLUMNS {
            let mut st = self
                .conn
                .prepare("SELECT name, type FROM pragma_table_info(?1) ORDER BY cid")
                .map_err(|e| self.err(e))?;
            let have: Vec<(String, String)> = st
                .query_map([table], |r| Ok((r.get(0)?, r.get(1)?)))
                .and_then(|rows| rows.collect())
                .map_err(|e| self.err(e))?;
            if have.is_empty() {
                out.push(format!("table {table} is missing"));
                tables_ok = false;
                continue;
            }
            let want: Vec<(String, String)> = want
                .iter()
                .map(|(n, t)| (n.to_string(), t.to_string()))
                .collect();
            if have != want {
                let show = |v: &[(String, String)]| {
                    v.iter()
                        .map(|(n, t)| format!("{n} {t}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                out.push(format!(
                    "table {table} has columns ({}), expected ({})",
                    crate::output::head(&show(&have), 300),
                    show(&want)
                ));
                tables_ok = false;
            }
        }
        if !tables_ok {
            return Ok(out);
        }
        for (table, col) in NUMERIC {
            let bad = q(&format!(
                "SELECT count(*) FROM {table} WHERE {col} IS NOT NULL AND typeof({col}) NOT IN ('real', 'integer')"
            ))?;
            if bad > 0 {
                out.push(format!("{table}.{col}: {bad} values that are not numbers"));
            }
        }
        let orphans = q("SELECT (SELECT count(*) FROM metrics WHERE run_id NOT IN (SELECT id FROM runs)) + (SELECT count(*) FROM samples WHERE run_id NOT IN (SELECT id FROM runs)) + (SELECT count(*) FROM findings WHERE run_id NOT IN (SELECT id FROM runs))")?;
        if orphans > 0 {
            out.push(format!("{orphans} rows belong to no night"));
        }
        // Each night's metrics, measured or failed, against the most any night of its suite file
        // holds: a night cut short holds fewer.
        let mut st = self
            .conn
            .prepare(
                "SELECT r.id, r.suite_sha256,
                    (SELECT count(*) FROM metrics m WHERE m.run_id = r.id)
                  + (SELECT count(*) FROM findings f WHERE f.run_id = r.id AND f.verdict = 'failed'
                       AND f.name NOT IN (SELECT name FROM metrics m2 WHERE m2.run_id = r.id))
                 FROM runs r ORDER BY r.id",
            )
            .map_err(|e| self.err(e))?;
        let nights: Vec<(i64, String, i64)> = st
            .query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))
            .and_then(|rows| rows.collect())
            .map_err(|e| self.err(e))?;
        let mut most: std::collections::HashMap<&str, i64> = Default::default();
        for (_, sha, n) in &nights {
            let m = most.entry(sha.as_str()).or_insert(0);
            *m = (*m).max(*n);
        }
        for (id, sha, n) in &nights {
            let want = most[sha.as_str()];
            if *n < want {
                out.push(format!(
                    "night {id} holds {n} of its suite's {want} metrics"
                ));
            }
        }
        Ok(out)
    }

    fn err(&self, e: rusqlite::Error) -> crate::error::Failure {
        db_err(&self.path, e)
    }

    /// Writes a whole night in one transaction; returns its id.
    pub fn append(&mut self, n: &Night) -> Result<i64> {
        let path = self.path.clone();
        let e = |e| db_err(&path, e);
        let tx = self
            .conn
            .transaction_with_behavior(rusqlite::TransactionBehavior::Immediate)
            .map_err(e)?;
        let regressions = n
            .findings
            .iter()
            .filter(|f| f.verdict == "regression" || f.verdict == "failed")
            .count() as i64;
        tx.execute(
            "INSERT INTO runs(suite, suite_sha256, started_at, finished_at, git_commit, git_dirty,
             fingerprint, env_json, wall_s, regressions, note) VALUES (?1,?2,?3,?4,?5,?6,?7,?8,?9,?10,?11)",
            params![
                n.suite,
                n.suite_sha256,
                n.started_at,
                n.finished_at,
                n.git_commit,
                n.git_dirty,
                n.fingerprint,
                n.env_json,
                n.wall_s,
                regressions,
                n.note
            ],
        )
        .map_err(e)?;
        let id = tx.last_insert_rowid();
        {
            let mut m = tx
                .prepare(
                    "INSERT INTO metrics(run_id, name, kind, unit, value, gated) VALUES (?1,?2,?3,?4,?5,?6)",
                )
                .map_err(e)?;
            let mut s = tx
                .prepare("INSERT INTO samples(run_id, name, idx, value) VALUES (?1,?2,?3,?4)")
                .map_err(e)?;
            for metric in &n.metrics {
                m.execute(params![
                    id,
                    metric.name,
                    metric.kind,
                    metric.unit,
                    metric.value,
                    metric.gated
                ])
                .map_err(e)?;
                for (i, v) in metric.samples.iter().enumerate() {
                    s.execute(params![id, metric.name, i as i64, v])
                        .map_err(e)?;
                }
            }
            let mut f = tx
                .prepare(
                    "INSERT INTO findings(run_id, name, verdict, baseline, value, change_pct, message)
                     VALUES (?1,?2,?3,?4,?5,?6,?7)",
                )
                .map_err(e)?;
            for x in &n.findings {
                f.execute(params![
                    id,
                    x.name,
                    x.verdict,
                    x.baseline,
                    x.value,
                    x.change_pct,
                    x.message
                ])
                .map_err(e)?;
            }
        }
        tx.commit().map_err(e)?;
        Ok(id)
    }

    /// Nights, oldest first; only those of `fingerprint` and `suite` when given.
    pub fn runs(&self, fingerprint: Option<&str>, suite: Option<&str>) -> Result<Vec<RunRow>> {
        let mut st = self
            .conn
            .prepare(
                "SELECT id, suite, started_at, git_commit, git_dirty, fingerprint, wall_s, regressions, note,
                 (SELECT count(*) FROM metrics m WHERE m.run_id = runs.id)
                 FROM runs WHERE (?1 IS NULL OR fingerprint = ?1) AND (?2 IS NULL OR suite = ?2) ORDER BY id",
            )
            .map_err(|e| self.err(e))?;
        let rows = st
            .query_map(params![fingerprint, suite], |r| {
                Ok(RunRow {
                    id: r.get(0)?,
                    suite: r.get(1)?,
                    started_at: r.get(2)?,
                    git_commit: r.get(3)?,
                    git_dirty: r.get(4)?,
                    fingerprint: r.get(5)?,
                    wall_s: r.get(6)?,
                    regressions: r.get(7)?,
                    note: r.get(8)?,
                    metrics: r.get(9)?,
                })
            })
            .map_err(|e| self.err(e))?;
        rows.collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| self.err(e))
    }

    /// One night's row.
    pub fn run(&self, id: i64) -> Result<Option<RunRow>> {
        Ok(self.runs(None, None)?.into_iter().find(|r| r.id == id))
    }

    /// The environment JSON of a night.
    pub fn env_json(&self, id: i64) -> Result<Option<String>> {
        self.conn
            .query_row("SELECT env_json FROM runs WHERE id = ?1", [id], |r| {
                r.get(0)
            })
            .optional()
            .map_err(|e| self.err(e))
    }

    /// A night's metrics with their samples, by name.
    pub fn metrics(&self, run_id: i64) -> Result<Vec<Metric>> {
        let mut st = self
            .conn
            .prepare("SELECT name, kind, unit, value, gated FROM metrics WHERE run_id = ?1 ORDER BY name")
            .map_err(|e| self.err(e))?;
        let mut out: Vec<Metric> = st
            .query_map([run_id], |r| {
                Ok(Metric {
                    name: r.get(0)?,
                    kind: r.get(1)?,
                    unit: r.get(2)?,
                    value: r.get(3)?,
                    gated: r.get(4)?,
                    samples: Vec::new(),
                })
            })
            .map_err(|e| self.err(e))?
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| self.err(e))?;
        let mut st = self
            .conn
            .prepare("SELECT name, value FROM samples WHERE run_id = ?1 ORDER BY name, idx")
            .map_err(|e| self.err(e))?;
        let samples: Vec<(String, f64)> = st
            .query_map([run_id], |r| Ok((r.get(0)?, r.get(1)?)))
            .map_err(|e| self.err(e))?
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| self.err(e))?;
        for (name, v) in samples {
            if let Ok(i) = out.binary_search_by(|m| m.name.as_str().cmp(&name)) {
                out[i].samples.push(v);
            }
        }
        Ok(out)
    }

    /// A night's findings.
    pub fn findings(&self, run_id: i64) -> Result<Vec<Finding>> {
        let mut st = self
            .conn
            .prepare(
                "SELECT name, verdict, baseline, value, change_pct, message FROM findings WHERE run_id = ?1 ORDER BY rowid",
            )
            .map_err(|e| self.err(e))?;
        let rows = st
            .query_map([run_id], |r| {
                Ok(Finding {
                    name: r.get(0)?,
                    verdict: r.get(1)?,
                    baseline: r.get(2)?,
                    value: r.get(3)?,
                    change_pct: r.get(4)?,
                    message: r.get(5)?,
                })
            })
            .map_err(|e| self.err(e))?;
        rows.collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| self.err(e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn night(note: &str) -> Night {
        Night {
            suite: "s".into(),
            suite_sha256: "x".into(),
            started_at: "2026-01-01T00:00:00Z".into(),
            finished_at: "2026-01-01T00:01:00Z".into(),
            git_commit: "abc".into(),
            git_dirty: false,
            fingerprint: "fp".into(),
            env_json: "{}".into(),
            wall_s: 1.0,
            note: Some(note.into()),
            metrics: vec![Metric {
                name: "ratio:grid tetra1@1".into(),
                kind: "time_ratio".into(),
                unit: "ratio".into(),
                value: 1.5,
                gated: true,
                samples: vec![1.4, 1.5, 1.6],
            }],
            findings: vec![],
        }
    }

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("rtbench-history-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d.join("h.sqlite")
    }

    #[test]
    fn a_night_round_trips_with_its_samples() {
        let p = tmp("rt");
        let mut h = History::open(&p, true).unwrap();
        let id = h.append(&night("a")).unwrap();
        let h = History::open(&p, false).unwrap();
        let m = h.metrics(id).unwrap();
        assert_eq!(m, night("a").metrics);
        assert_eq!(h.runs(Some("fp"), Some("s")).unwrap().len(), 1);
        assert_eq!(h.runs(Some("other"), None).unwrap().len(), 0);
        assert!(h.problems().unwrap().is_empty());
    }

    #[test]
    fn a_newer_schema_and_a_file_that_is_not_sqlite_are_refused_in_one_line() {
        let p = tmp("newer");
        History::open(&p, true).unwrap();
        Connection::open(&p)
            .unwrap()
            .pragma_update(None, "user_version", SCHEMA + 1)
            .unwrap();
        let e = History::open(&p, false).err().unwrap().to_string();
        assert!(e.contains("newer than this rtbench"), "{e}");
        assert!(e.starts_with(&p.display().to_string()) && e.lines().count() == 1);

        let q = tmp("junk");
        std::fs::write(
            &q,
            "this is not a database, only some text long enough\n".repeat(40),
        )
        .unwrap();
        let e = History::open(&q, false).err().unwrap().to_string();
        assert!(e.contains("not a database"), "{e}");
        assert_eq!(e.lines().count(), 1);
    }

    #[test]
    fn two_writers_both_land() {
        let p = tmp("two");
        History::open(&p, true).unwrap();
        let threads: Vec<_> = (0..2)
            .map(|i| {
                let p = p.clone();
                std::thread::spawn(move || {
                    let mut h = History::open(&p, true).unwrap();
                    for _ in 0..20 {
                        h.append(&night(&format!("w{i}"))).unwrap();
                    }
                })
            })
            .collect();
        for t in threads {
            t.join().unwrap();
        }
        let h = History::open(&p, false).unwrap();
        assert_eq!(h.runs(None, None).unwrap().len(), 40);
    }

    /// Read commands open read-only: an empty file is refused and stays empty, and a history
    /// reads from a read-only directory.
    #[test]
    fn reading_never_writes() {
        let p = tmp("ro");
        std::fs::write(&p, b"").unwrap();
        let e = History::open_read(&p).err().unwrap().to_string();
        assert!(e.contains("no history"), "{e}");
        assert_eq!(std::fs::metadata(&p).unwrap().len(), 0);
        std::fs::remove_file(&p).unwrap();
        History::open(&p, true)
            .unwrap()
            .append(&night("a"))
            .unwrap();
        let dir = p.parent().unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o555)).unwrap();
        let h = History::open_read(&p);
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o755)).unwrap();
        let h = h.unwrap();
        assert_eq!(h.runs(None, None).unwrap().len(), 1);
        assert!(h.problems().unwrap().is_empty());
    }

    /// `history check` finds what integrity_check does not: a dropped table, a renamed column,
    /// text among numbers, a night cut short.
    #[test]
    fn check_sees_schema_types_and_short_nights() {
        let damage = |tag: &str, sql: &str, needle: &str| {
            let p = tmp(tag);
            let mut h = History::open(&p, true).unwrap();
            let mut full = night("full");
            full.metrics.push(Metric {
                name: "counter:grid tetra1@1/nodes".into(),
                kind: "counter".into(),
                unit: "1".into(),
                value: 7.0,
                gated: true,
                samples: vec![7.0],
            });
            h.append(&full).unwrap();
            h.append(&night("short")).unwrap();
            drop(h);
            let c = Connection::open(&p).unwrap();
            c.execute_batch(sql).unwrap();
            drop(c);
            let problems = History::open_read(&p).unwrap().problems().unwrap();
            assert!(
                problems.iter().any(|l| l.contains(needle)),
                "{tag}: {problems:?}"
            );
        };
        damage("short", "", "night 2 holds 1 of its suite's 2 metrics");
        damage("drop", "DROP TABLE samples;", "table samples is missing");
        damage(
            "rename",
            "ALTER TABLE findings RENAME COLUMN message TO msg;",
            "table findings has columns",
        );
        damage(
            "text",
            "UPDATE metrics SET value = 'fast' WHERE run_id = 1;",
            "metrics.value",
        );
    }
}
