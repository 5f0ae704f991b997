//! A camera kept in the repository as data (`data/views/*.json`): a view the seed names but does
//! not give, such as seed 000's rings368m (§4.4, Table 4.3). The file holds the NFF view
//! (`from`, `at`, `up`, `angle` in degrees, `hither`) under `"view"`, and its own source notes.

use crate::error::{input, Result};
use glam::DVec3;
use rtbench_scenes::View;
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
struct Raw {
    from: [f64; 3],
    at: [f64; 3],
    up: [f64; 3],
    angle: f64,
    #[serde(default)]
    hither: f64,
}

#[derive(Deserialize)]
struct RawFile {
    view: Raw,
}

pub struct ViewFile {
    pub view: View,
}

impl ViewFile {
    pub fn parse(text: &str, what: &str) -> Result<ViewFile> {
        let f: RawFile = serde_json::from_str(text)
            .map_err(|e| input(format!("{what}: not a view file ({e})")))?;
        let r = f.view;
        let (from, at, up) = (DVec3::from(r.from), DVec3::from(r.at), DVec3::from(r.up));
        let dir = at - from;
        if !(r.angle > 0.0 && r.angle < 180.0 && dir.is_finite())
            || dir.length() == 0.0
            || dir.cross(up).length() == 0.0
            || !r.hither.is_finite()
        {
            return Err(input(format!(
                "{what}: the view needs from ≠ at, up not along the view direction and 0 < angle < 180"
            )));
        }
        Ok(ViewFile {
            view: View {
                from,
                at,
                up,
                angle: r.angle,
                hither: r.hither,
                resolution: [512, 512],
            },
        })
    }

    pub fn read(path: &Path) -> Result<ViewFile> {
        let text =
            std::fs::read_to_string(path).map_err(|e| input(format!("{}: {e}", path.display())))?;
        Self::parse(&text, &path.display().to_string())
    }
}
