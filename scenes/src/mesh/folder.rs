//! Reading the files a mesh names (glTF buffers) without ever leaving the mesh's own folder.
//!
//! A URI inside a mesh file is data from whoever wrote the file, not a path the user chose:
//! it may name only a regular file below the folder holding the mesh, by a relative path
//! without `..`, and a read never takes more than the length the file declares.

use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// Decodes `%XX` escapes of a URI reference (RFC 3986); refuses a malformed escape.
fn percent_decode(uri: &str) -> Result<String, String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or("a malformed %-escape in a buffer URI")?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "a buffer URI that is not UTF-8".to_string())
}

/// The file below `dir` that the relative URI `uri` names, or why it may not be read.
pub fn resolve(dir: &Path, uri: &str) -> Result<PathBuf, String> {
    let rel = percent_decode(uri)?;
    let refuse = |why: &str| Err(format!("buffer URI {:?}: {why}", shorten(&rel, 80)));
    if rel.is_empty() {
        return refuse("empty");
    }
    if rel.contains(':') || rel.contains('\\') || rel.contains('\0') {
        // A scheme (file:, http:), a drive letter or a Windows path: never a relative path.
        return refuse("only relative paths inside the mesh's folder and data: URIs are read");
    }
    let p = Path::new(&rel);
    for c in p.components() {
        match c {
            Component::Normal(_) | Component::CurDir => {}
            Component::ParentDir => return refuse("'..' leaves the mesh's folder"),
            Component::RootDir | Component::Prefix(_) => {
                return refuse("an absolute path leaves the mesh's folder")
            }
        }
    }
    let base = std::fs::canonicalize(dir).map_err(|e| format!("the mesh's folder: {e}"))?;
    let full = std::fs::canonicalize(base.join(p)).map_err(|e| {
        format!(
            "buffer {:?}: {}",
            shorten(&rel, 80),
            e.kind().to_string().to_lowercase()
        )
    })?;
    if !full.starts_with(&base) {
        return refuse("a link that leaves the mesh's folder");
    }
    let meta = std::fs::metadata(&full).map_err(|e| format!("buffer {rel:?}: {e}"))?;
    if !meta.is_file() {
        return refuse("not a regular file");
    }
    Ok(full)
}

/// Exactly `len` bytes from the start of `path`: an error when the file is shorter, and never
/// a byte more read or allocated than the file holds.
pub fn read_exact_len(path: &Path, len: u64) -> Result<Vec<u8>, String> {
    let f = std::fs::File::open(path).map_err(|e| format!("cannot read: {e}"))?;
    let have = f.metadata().map_err(|e| format!("cannot read: {e}"))?.len();
    if have < len {
        return Err(format!("holds {have} bytes, {len} declared"));
    }
    let mut out = Vec::with_capacity(len as usize);
    f.take(len)
        .read_to_end(&mut out)
        .map_err(|e| format!("cannot read: {e}"))?;
    if (out.len() as u64) < len {
        return Err(format!("holds {} bytes, {len} declared", out.len()));
    }
    Ok(out)
}

/// At most `max` characters of `s` (never cut inside a character), with `…` when cut.
pub fn shorten(s: &str, max: usize) -> String {
    match s.char_indices().nth(max) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_files_below_the_folder_resolve() {
        let root = std::env::temp_dir().join(format!("rtbench-folder-{}", std::process::id()));
        let dir = root.join("mesh");
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(dir.join("sub/b.bin"), [1u8; 8]).unwrap();
        std::fs::write(root.join("secret"), b"x").unwrap();
        assert!(resolve(&dir, "sub/b.bin").is_ok());
        assert!(resolve(&dir, "./sub/%62.bin").is_ok());
        for bad in [
            "/etc/passwd",
            "../secret",
            "sub/../../secret",
            "%2E%2E/secret",
            "file:///etc/passwd",
            "C:/x",
            "",
            "sub",
            "%zz",
        ] {
            assert!(resolve(&dir, bad).is_err(), "{bad}");
        }
        #[cfg(unix)]
        {
            let _ = std::os::unix::fs::symlink("/dev/zero", dir.join("z.bin"));
            let _ = std::os::unix::fs::symlink(root.join("secret"), dir.join("s.bin"));
            assert!(resolve(&dir, "z.bin").is_err());
            assert!(resolve(&dir, "s.bin").is_err());
        }
        let p = dir.join("sub/b.bin");
        assert_eq!(read_exact_len(&p, 4).unwrap(), vec![1u8; 4]);
        assert!(read_exact_len(&p, 9).is_err());
        assert_eq!(shorten("日日日日日", 2), "日日…");
        std::fs::remove_dir_all(&root).unwrap();
    }
}
