//! NFF reader for user scenes and fixtures. Streams records into a [`Sink`]; every error names
//! the file and line. Accepts what the SPD programs print and the NFF spec allows (docs/NFF.TXT
//! of SPD 3.14): `#` comments, records split over lines, `l` with an optional colour.

use crate::model::{Light, Material, ShapeRef, View};
use crate::sink::Sink;
use crate::validate;
use glam::DVec3;
use std::io::Read;
use std::path::Path;

/// A malformed NFF input: where, and what.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{file}:{line}: {message}")]
pub struct NffError {
    pub file: String,
    /// 1-based; 0 when the file could not be read at all.
    pub line: usize,
    pub message: String,
}

/// Largest vertex count accepted for one polygon. A corrupt count must not ask for gigabytes, and
/// triangulating a concave polygon (ear clipping) is quadratic: 0.8 s for a 16,384-vertex star
/// polygon, where 100,000 vertices took 18.9 s. The SPD's largest polygons have 144 vertices.
pub const MAX_VERTICES: usize = 1 << 14;

/// A token as errors show it: at most 40 characters (then `…`), control characters escaped, so
/// that one error stays one short line whatever the input holds.
pub fn shown(t: &str) -> String {
    shown_upto(t, 40)
}

/// [`shown`] with room for `max` characters (file names).
pub fn shown_upto(t: &str, max: usize) -> String {
    let mut s = String::new();
    for c in t.chars().take(max) {
        if c.is_control() {
            s.extend(c.escape_default());
        } else {
            s.push(c);
        }
    }
    if t.chars().nth(max).is_some() {
        s.push('…');
    }
    s
}

struct Tokens<'a> {
    file: &'a str,
    text: &'a str,
    pos: usize,
    line: usize,
    /// Line of the token last returned.
    tok_line: usize,
}

impl<'a> Tokens<'a> {
    fn err(&self, message: String) -> NffError {
        NffError {
            file: self.file.to_string(),
            line: self.tok_line.max(1),
            message,
        }
    }

    /// Next whitespace-separated token, skipping `#` comments to the end of their line.
    fn next(&mut self) -> Option<&'a str> {
        let b = self.text.as_bytes();
        loop {
            while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
                if b[self.pos] == b'\n' {
                    self.line += 1;
                }
                self.pos += 1;
            }
            if self.pos < b.len() && b[self.pos] == b'#' {
                while self.pos < b.len() && b[self.pos] != b'\n' {
                    self.pos += 1;
                }
                continue;
            }
            break;
        }
        if self.pos >= b.len() {
            // At the end, errors name the line of the last token read.
            return None;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        self.tok_line = self.line;
        Some(&self.text[start..self.pos])
    }

    /// True when the next token starts on the current line (for optional trailing fields).
    fn more_on_line(&self) -> bool {
        let b = self.text.as_bytes();
        let mut p = self.pos;
        while p < b.len() && b[p] != b'\n' && b[p].is_ascii_whitespace() {
            p += 1;
        }
        p < b.len() && b[p] != b'\n' && b[p] != b'#'
    }

    fn number(&mut self, what: &str) -> Result<f64, NffError> {
        let t = self
            .next()
            .ok_or_else(|| self.err(format!("unexpected end of file: expected {what}")))?;
        let x: f64 = t
            .parse()
            .map_err(|_| self.err(format!("expected a number ({what}), found '{}'", shown(t))))?;
        if !x.is_finite() {
            return Err(self.err(format!("{what} is not finite: '{}'", shown(t))));
        }
        Ok(x)
    }

    fn vec3(&mut self, what: &str) -> Result<DVec3, NffError> {
        Ok(DVec3::new(
            self.number(what)?,
            self.number(what)?,
            self.number(what)?,
        ))
    }

    fn keyword(&mut self, want: &str) -> Result<(), NffError> {
        match self.next() {
            Some(t) if t == want => Ok(()),
            Some(t) => Err(self.err(format!(
                "expected '{want}' in the view block, found '{}'",
                shown(t)
            ))),
            None => Err(self.err(format!("unexpected end of file: expected '{want}'"))),
        }
    }

    fn count(&mut self, what: &str) -> Result<usize, NffError> {
        let t = self
            .next()
            .ok_or_else(|| self.err(format!("unexpected end of file: expected {what}")))?;
        let n: usize = t
            .parse()
            .map_err(|_| self.err(format!("expected a vertex count, found '{}'", shown(t))))?;
        if !(3..=MAX_VERTICES).contains(&n) {
            return Err(self.err(format!("{what} {n} out of range (3 to {MAX_VERTICES})")));
        }
        Ok(n)
    }
}

/// Checks a primitive (crate::validate) and passes it on.
fn shape(t: &Tokens<'_>, sink: &mut dyn Sink, s: ShapeRef<'_>) -> Result<(), NffError> {
    validate::check_shape(s).map_err(|e| t.err(e))?;
    sink.shape(s);
    Ok(())
}

/// Reads NFF text into `sink`. `file` names the input in errors.
pub fn read_nff(text: &str, file: &str, sink: &mut dyn Sink) -> Result<(), NffError> {
    let mut t = Tokens {
        file,
        text,
        pos: 0,
        line: 1,
        tok_line: 1,
    };
    let mut verts = Vec::new();
    let mut norms = Vec::new();
    while let Some(word) = t.next() {
        match word {
            "v" => {
                t.keyword("from")?;
                let from = t.vec3("from")?;
                t.keyword("at")?;
                let at = t.vec3("at")?;
                t.keyword("up")?;
                let up = t.vec3("up")?;
                t.keyword("angle")?;
                let angle = t.number("angle")?;
                t.keyword("hither")?;
                let hither = t.number("hither")?;
                t.keyword("resolution")?;
                let rx = t.number("resolution")?;
                let ry = t.number("resolution")?;
                if rx < 1.0
                    || ry < 1.0
                    || rx.fract() != 0.0
                    || ry.fract() != 0.0
                    || rx > 1e6
                    || ry > 1e6
                {
                    return Err(t.err(format!(
                        "resolution must be whole numbers from 1 to 1e6, got {rx} {ry}"
                    )));
                }
                let view = View {
                    from,
                    at,
                    up,
                    angle,
                    hither,
                    resolution: [rx as u32, ry as u32],
                };
                validate::check_view(&view).map_err(|e| t.err(e))?;
                sink.view(&view);
            }
            "b" => {
                let c = t.vec3("background colour")?;
                validate::check_background(c).map_err(|e| t.err(e))?;
                sink.background(c);
            }
            "l" => {
                let position = t.vec3("light position")?;
                let color = if t.more_on_line() {
                    Some(t.vec3("light colour")?)
                } else {
                    None
                };
                let light = Light { position, color };
                validate::check_light(&light).map_err(|e| t.err(e))?;
                sink.light(&light);
            }
            "f" => {
                let color = t.vec3("fill colour")?;
                let kd = t.number("Kd")?;
                let ks = t.number("Ks")?;
                let shine = t.number("Shine")?;
                let tr = t.number("T")?;
                let ior = t.number("index of refraction")?;
                let material = Material {
                    color,
                    kd,
                    ks,
                    shine,
                    t: tr,
                    ior,
                };
                validate::check_material(&material).map_err(|e| t.err(e))?;
                sink.material(&material);
            }
            "s" => {
                let center = t.vec3("sphere centre")?;
                let radius = t.number("sphere radius")?;
                shape(&t, sink, ShapeRef::Sphere { center, radius })?;
            }
            "c" => {
                let base = t.vec3("cone base")?;
                let base_radius = t.number("cone base radius")?;
                let apex = t.vec3("cone apex")?;
                let apex_radius = t.number("cone apex radius")?;
                shape(
                    &t,
                    sink,
                    ShapeRef::Cone {
                        base,
                        base_radius,
                        apex,
                        apex_radius,
                    },
                )?;
            }
            "p" => {
                let n = t.count("polygon vertex count")?;
                verts.clear();
                for _ in 0..n {
                    verts.push(t.vec3("polygon vertex")?);
                }
                shape(&t, sink, ShapeRef::Polygon(&verts))?;
            }
            "pp" => {
                let n = t.count("patch vertex count")?;
                verts.clear();
                norms.clear();
                for _ in 0..n {
                    verts.push(t.vec3("patch vertex")?);
                    norms.push(t.vec3("patch normal")?);
                }
                shape(
                    &t,
                    sink,
                    ShapeRef::Patch {
                        vertices: &verts,
                        normals: &norms,
                    },
                )?;
            }
            other => {
                return Err(t.err(format!("unknown directive '{}'", shown(other))));
            }
        }
    }
    Ok(())
}

/// Reads an NFF file (plain, or gzip when the name ends `.gz` is not supported: decompress
/// first) into `sink`.
pub fn read_nff_file(path: &Path, sink: &mut dyn Sink) -> Result<(), NffError> {
    let file = path.display().to_string();
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(|e| NffError {
            file: file.clone(),
            line: 0,
            message: format!("cannot read: {e}"),
        })?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        NffError {
            file: file.clone(),
            line,
            message: "not UTF-8 text".into(),
        }
    })?;
    read_nff(text, &file, sink)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::{CountingSink, SceneCollector};

    fn err(text: &str) -> NffError {
        read_nff(text, "x.nff", &mut CountingSink::default()).unwrap_err()
    }

    #[test]
    fn reads_records() {
        let text = "b 0.1 0.2 0.3\nv\nfrom 0 0 -8\nat 0 0 0\nup 0 1 0\nangle 25\nhither 0.001\nresolution 256 256\n\
                    l -10 3 -20\nl 1 2 3 1 1 1 # coloured\nf 1 0 0 0.7 0.3 10 0 1\ns 0 0 0 1\n\
                    c 0 0 0 1\n0 1 0 0.5\np 3\n0 0 0\n1 0 0\n0 1 0\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n";
        let mut c = SceneCollector::default();
        read_nff(text, "t", &mut c).unwrap();
        let s = c.scene;
        assert_eq!(s.lights.len(), 2);
        assert_eq!(s.lights[1].color, Some(DVec3::ONE));
        assert_eq!(s.objects.len(), 4);
        assert_eq!(s.view.resolution, [256, 256]);
    }

    #[test]
    fn errors_name_file_and_line() {
        assert_eq!(
            err("p 3\n0 0 0\n1 0 0\n").to_string(),
            "x.nff:3: unexpected end of file: expected polygon vertex"
        );
        assert_eq!(err("s 0 0 zero 1\n").line, 1);
        assert!(err("s 0 0 zero 1\n").message.contains("'zero'"));
        assert!(err("\n\ns 0 0 nan 1").message.contains("not finite"));
        assert_eq!(err("\n\ns 0 0 nan 1").line, 3);
        assert!(err("s 0 0 inf 1").message.contains("not finite"));
        assert!(err("q 1 2 3").message.contains("unknown directive 'q'"));
        assert!(err("p 99999999999\n").message.contains("out of range"));
        assert!(err("p 2\n0 0 0\n1 1 1\n").message.contains("out of range"));
    }

    #[test]
    fn missing_file() {
        let e = read_nff_file(
            Path::new("/nonexistent/x.nff"),
            &mut CountingSink::default(),
        )
        .unwrap_err();
        assert_eq!(e.line, 0);
        assert!(e
            .to_string()
            .starts_with("/nonexistent/x.nff:0: cannot read"));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..400)) {
            let text = String::from_utf8_lossy(&bytes);
            let _ = read_nff(&text, "fuzz", &mut CountingSink::default());
        }

        #[test]
        fn nff_like_tokens_never_panic(words in proptest::collection::vec(
            proptest::sample::select(vec!["v","from","at","up","angle","hither","resolution","b","l","f","s","c","p","pp",
                "0","1","-2.5","3","1e9","nan","inf","x","#","\n","4","100000000"]), 0..80)) {
            let text = words.join(" ");
            let _ = read_nff(&text, "fuzz", &mut CountingSink::default());
        }
    }
}
