//! Where a command's scene comes from: an SPD program at a size factor, an NFF file, or a mesh
//! file (OBJ, PLY, glTF: `rtbench_scenes::mesh`, with a default camera, light and material).

use crate::error::{input, Result};
use rtbench_scenes::spd::{self, MountHash, Options, Program};
use rtbench_scenes::validate::Validating;
use rtbench_scenes::{nff, room, Scene, SceneCollector, Sink};
use std::path::PathBuf;

/// Hex digits of a scene file's content hash in its run label.
pub const FILE_HASH_DIGITS: usize = 12;

/// `<program|FILE.nff> [--sf N] [--tessellate [RES]] [--hash …]`, resolved.
#[derive(Clone, Debug)]
pub enum Source {
    Program(Program, Options),
    File(PathBuf),
    /// Seed 003's room stand-in ([`rtbench_scenes::room`]) at this many patches per metre:
    /// `room` (8) or `roomN`.
    Room(u32),
}

impl Source {
    pub fn resolve(
        scene: &str,
        sf: Option<u32>,
        tessellate: Option<u32>,
        hash: Option<MountHash>,
    ) -> Result<Source> {
        if let Some(rest) = scene.strip_prefix("room") {
            let ppm = if rest.is_empty() {
                Some(room::DEFAULT_PPM)
            } else {
                rest.parse::<u32>().ok()
            };
            if let Some(ppm) = ppm {
                if sf.is_some() || tessellate.is_some() || hash.is_some() {
                    return Err(input(format!(
                        "{scene}: --sf, --tessellate and --hash apply to SPD programs (room: roomN, N patches per metre)"
                    )));
                }
                room::patch_count(ppm).map_err(|e| input(e.to_string()))?;
                return Ok(Source::Room(ppm));
            }
        }
        if let Ok(program) = scene.parse::<Program>() {
            let mut opts = Options::standard(program);
            if let Some(sf) = sf {
                opts.size_factor = sf;
            }
            opts.tessellate = tessellate;
            if let Some(h) = hash {
                if program != Program::Mount {
                    return Err(input(format!(
                        "--hash applies to mount only, not {program}"
                    )));
                }
                opts.hash = h;
            }
            spd::validate(program, &opts)?;
            return Ok(Source::Program(program, opts));
        }
        let path = PathBuf::from(scene);
        if !scene.ends_with(".nff") && !path.exists() {
            // Neither a program nor a file: say both.
            let msg = format!(
                "{}; nor is '{scene}' an NFF, OBJ, PLY or glTF file",
                scene.parse::<Program>().unwrap_err()
            );
            return Err(input(nff::read::shown_upto(&msg, 400)));
        }
        if sf.is_some() || hash.is_some() {
            return Err(input(format!(
                "--sf and --hash apply to SPD programs, not to the file {scene}"
            )));
        }
        if tessellate.is_some() {
            return Err(input(format!(
                "--tessellate applies to SPD programs, not to the file {scene}"
            )));
        }
        match std::fs::metadata(&path) {
            Err(e) => return Err(input(format!("{}: {e}", nff::read::shown_upto(scene, 200)))),
            Ok(m) if m.is_dir() => {
                let shown = nff::read::shown_upto(scene, 200);
                let store = rtbench_engines::store::HEADER_FILE;
                let why = if path.join(rtbench_engines::store::SEGMENTS_FILE).is_file() {
                    format!("a scene store still being written (no {store} yet: finish it with --resume)")
                } else if ["bbox.bin", "objects.bin", "materials.bin", "geometry.bin"]
                    .iter()
                    .any(|f| path.join(f).exists())
                {
                    format!(
                        "a scene store without its {store} (unfinished or damaged: write it again)"
                    )
                } else {
                    format!("a directory, neither a scene file nor a scene store (no {store})")
                };
                return Err(input(format!("{shown}: {why}")));
            }
            Ok(m) if !m.is_file() => {
                return Err(input(format!(
                    "{}: not a regular file",
                    nff::read::shown_upto(scene, 200)
                )))
            }
            Ok(_) => {}
        }
        Ok(Source::File(path))
    }

    /// Streams the scene into `sink`, never holding it.
    pub fn stream(&self, sink: &mut dyn Sink) -> Result<()> {
        match self {
            Source::Program(p, o) => {
                // Generated scenes pass the same checks as files (rtbench_scenes::validate).
                let mut v = Validating::new(sink);
                spd::generate(*p, o, &mut v)?;
                v.finish()
                    .map_err(|e| input(format!("{}: {e}", self.label())))
            }
            Source::File(path) if rtbench_scenes::mesh::Format::of(path).is_some() => {
                // OBJ, PLY, glTF: checked like every other scene.
                let mut v = Validating::new(sink);
                rtbench_scenes::mesh::stream_mesh(path, &mut v)
                    .map_err(|e| input(e.to_string()))?;
                v.finish()
                    .map_err(|e| input(format!("{}: {e}", self.label())))
            }
            Source::File(path) => Ok(nff::read_nff_file(path, sink)?),
            Source::Room(ppm) => {
                let mut v = Validating::new(sink);
                room::generate(*ppm, &mut v).map_err(|e| input(e.to_string()))?;
                v.finish()
                    .map_err(|e| input(format!("{}: {e}", self.label())))
            }
        }
    }

    pub fn load(&self) -> Result<Scene> {
        let mut c = SceneCollector::default();
        self.stream(&mut c)?;
        let mut s = c.scene;
        s.name = self.label();
        Ok(s)
    }

    /// `balls4`, `balls4-tess3`, `mount6-jenkins`, or the file's name.
    pub fn label(&self) -> String {
        match self {
            Source::Program(p, o) => {
                let mut s = format!("{}{}", p.name(), o.size_factor);
                if o.hash == MountHash::Jenkins {
                    s.push_str("-jenkins");
                }
                if let Some(r) = o.tessellate {
                    s.push_str(&format!("-tess{r}"));
                }
                s
            }
            Source::Room(ppm) => format!("room{ppm}"),
            Source::File(p) => p
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        }
    }

    /// SHA-256 of a scene file's content: the file, and for a glTF the buffers it names (each
    /// resolved inside the mesh's folder, as reading does). `None` for generated scenes.
    pub fn file_sha256(&self) -> Result<Option<String>> {
        let Source::File(path) = self else {
            return Ok(None);
        };
        let files = match rtbench_scenes::mesh::Format::of(path) {
            Some(_) => rtbench_scenes::mesh::files_read(path).map_err(|e| input(e.to_string()))?,
            None => vec![path.clone()],
        };
        use sha2::Digest;
        let mut h = sha2::Sha256::new();
        for f in &files {
            let mut file = std::fs::File::open(f)
                .map_err(|e| input(format!("{}: cannot read: {e}", f.display())))?;
            std::io::copy(&mut file, &mut h)
                .map_err(|e| input(format!("{}: cannot read: {e}", f.display())))?;
        }
        Ok(Some(crate::output::hex(&h.finalize())))
    }

    /// The scene's name in run keys and reports: [`Source::label`], and for a file its name with
    /// the first 12 hex digits of its content hash (`bunny.obj-3f9a1c2b7d4e`), so that a changed
    /// file is never taken for the same scene.
    pub fn run_label(&self) -> Result<String> {
        Ok(match self.file_sha256()? {
            Some(h) => format!("{}-{}", self.label(), &h[..FILE_HASH_DIGITS]),
            None => self.label(),
        })
    }

    pub fn program(&self) -> Option<Program> {
        match self {
            Source::Program(p, _) => Some(*p),
            Source::File(_) | Source::Room(_) => None,
        }
    }

    pub fn size_factor(&self) -> Option<u32> {
        match self {
            Source::Program(_, o) => Some(o.size_factor),
            Source::File(_) | Source::Room(_) => None,
        }
    }
}
