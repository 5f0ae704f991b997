//! Writing results: atomically (a temp file beside the target, then rename), so an interrupted
//! or failed write never leaves a half-written file.

use crate::error::{input, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Runs `write` on a temp file next to `path`, then renames it over `path`. On any error the
/// temp file is removed and the error names `path`.
pub fn write_atomic<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
{
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| input(format!("{}: not a file name", path.display())))?;
    let tmp: PathBuf = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> std::io::Result<()> {
        let f = std::fs::File::create(&tmp)?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, f);
        write(&mut w)?;
        w.flush()?;
        let f = w.into_inner().map_err(|e| e.into_error())?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(input(format!("{}: cannot write: {e}", path.display())));
    }
    Ok(())
}

/// Writes a square RGB8 image (`size`² pixels, rows top down) as a PNG, atomically.
pub fn write_png(path: &Path, pixels: &[u8], size: u32) -> Result<()> {
    write_atomic(path, |w| {
        image::write_buffer_with_format(
            w,
            pixels,
            size,
            size,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(std::io::Error::other)
    })
}

/// The first error writing to stdout (a full disk, a closed pipe when SIGPIPE is ignored):
/// later writes are skipped and `main` ends with it (exit 2), never a panic.
static STDOUT_ERROR: std::sync::Mutex<Option<std::io::Error>> = std::sync::Mutex::new(None);

/// What the crate's `print!`/`println!` do (they shadow std's, see main.rs): write to stdout,
/// keeping the first error instead of panicking.
pub fn write_stdout(args: std::fmt::Arguments<'_>) {
    let mut failed = STDOUT_ERROR.lock().unwrap_or_else(|e| e.into_inner());
    if failed.is_some() {
        return;
    }
    let mut o = std::io::stdout().lock();
    if let Err(e) = o.write_fmt(args) {
        *failed = Some(e);
    }
}

/// Flushes stdout; the first error any write to it met, if any.
pub fn stdout_status() -> Result<()> {
    let flushed = std::io::stdout().lock().flush();
    let mut failed = STDOUT_ERROR.lock().unwrap_or_else(|e| e.into_inner());
    match failed.take().map_or(flushed, Err) {
        Ok(()) => Ok(()),
        Err(e) => Err(input(format!("stdout: cannot write: {e}"))),
    }
}

/// Prints one JSON document on stdout (the `--json` contract).
pub fn print_json(v: &serde_json::Value) {
    println!(
        "{}",
        serde_json::to_string_pretty(v).expect("JSON values serialise")
    );
}

/// Bytes as lowercase hexadecimal (digests in results and manifests).
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
