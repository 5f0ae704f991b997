//! Writing results: atomically (a temp file beside the target, then rename), so an interrupted
//! or failed write never leaves a half-written file.

use crate::error::{input, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The first `n` characters of `s`: text read from files and databases is cut at a character,
/// never at a byte index (which panics inside a multi-byte character).
pub fn head(s: &str, n: usize) -> &str {
    s.char_indices().nth(n).map_or(s, |(i, _)| &s[..i])
}

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
    let _guard = interrupt::remove_on_signal(&tmp);
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

/// A temporary file or directory being written is removed if the process is interrupted (SIGINT,
/// SIGTERM, SIGHUP) before it is renamed into place: the handler unlinks the file, or runs
/// `rm -rf` on the directory (fork, execve and waitpid are async-signal-safe where walking a
/// directory is not), and then dies of the signal as it would have. One file and one directory at
/// a time, the latest registered.
pub mod interrupt {
    use std::ffi::{c_char, c_int, CString};
    use std::path::Path;
    use std::sync::atomic::{AtomicPtr, Ordering};
    use std::sync::Once;

    static TEMP: AtomicPtr<c_char> = AtomicPtr::new(std::ptr::null_mut());
    static TEMP_DIR: AtomicPtr<c_char> = AtomicPtr::new(std::ptr::null_mut());
    static INSTALL: Once = Once::new();

    extern "C" fn on_signal(sig: c_int) {
        let p = TEMP.swap(std::ptr::null_mut(), Ordering::SeqCst);
        let d = TEMP_DIR.swap(std::ptr::null_mut(), Ordering::SeqCst);
        // SAFETY: unlink, fork, execve, _exit, waitpid, signal and raise are async-signal-safe;
        // `p` and `d` are leaked CStrings, and the argument vector lives on this stack frame.
        unsafe {
            if !p.is_null() {
                libc::unlink(p);
            }
            if !d.is_null() {
                let argv: [*const c_char; 5] = [
                    c"rm".as_ptr(),
                    c"-rf".as_ptr(),
                    c"--".as_ptr(),
                    d,
                    std::ptr::null(),
                ];
                let env: [*const c_char; 1] = [std::ptr::null()];
                match libc::fork() {
                    0 => {
                        libc::execve(c"/bin/rm".as_ptr(), argv.as_ptr(), env.as_ptr());
                        libc::_exit(127);
                    }
                    pid if pid > 0 => {
                        libc::waitpid(pid, std::ptr::null_mut(), 0);
                    }
                    _ => {}
                }
            }
            libc::signal(sig, libc::SIG_DFL);
            libc::raise(sig);
        }
    }

    /// Clears the registration when the write is over.
    pub struct Guard(*mut c_char, &'static AtomicPtr<c_char>);

    impl Drop for Guard {
        fn drop(&mut self) {
            if self
                .1
                .compare_exchange(
                    self.0,
                    std::ptr::null_mut(),
                    Ordering::SeqCst,
                    Ordering::SeqCst,
                )
                .is_ok()
            {
                // SAFETY: the pointer came from CString::into_raw and is no longer shared.
                drop(unsafe { CString::from_raw(self.0) });
            }
        }
    }

    /// Removes the file `path` if a signal ends the process before the guard is dropped.
    pub fn remove_on_signal(path: &Path) -> Guard {
        register(path, &TEMP)
    }

    /// Removes the directory `path` and everything in it if a signal ends the process before the
    /// guard is dropped.
    pub fn remove_dir_on_signal(path: &Path) -> Guard {
        register(path, &TEMP_DIR)
    }

    fn register(path: &Path, slot: &'static AtomicPtr<c_char>) -> Guard {
        use std::os::unix::ffi::OsStrExt;
        INSTALL.call_once(|| {
            for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
                // SAFETY: installing a handler that only calls async-signal-safe functions.
                unsafe {
                    libc::signal(sig, on_signal as extern "C" fn(c_int) as libc::sighandler_t);
                }
            }
        });
        let c = CString::new(path.as_os_str().as_bytes())
            .unwrap_or_default()
            .into_raw();
        // The previous registration (a write still under way elsewhere) is left to its guard.
        slot.store(c, Ordering::SeqCst);
        Guard(c, slot)
    }
}

/// Bytes as lowercase hexadecimal (digests in results and manifests).
pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
