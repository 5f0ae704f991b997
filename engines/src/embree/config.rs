//! The `embree` engine's settings (listed in the module doc of [`super`]), parsed into a typed
//! configuration.

use crate::bvh::config::OnOff;
use crate::engine::{EngineError, Settings};

/// Typed configuration of the `embree` engine, parsed from `key=value` settings.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmbreeConfig {
    pub threads: u32,
    pub quality: Quality,
    pub robust: bool,
    pub compact: bool,
    pub isa: Option<String>,
    pub verbose: u32,
}

impl Default for EmbreeConfig {
    fn default() -> Self {
        EmbreeConfig {
            threads: 1,
            quality: Quality::Medium,
            robust: false,
            compact: false,
            isa: None,
            verbose: 0,
        }
    }
}

/// Embree's BVH build quality.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    Low,
    Medium,
    High,
}

impl std::str::FromStr for Quality {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "low" => Ok(Quality::Low),
            "medium" => Ok(Quality::Medium),
            "high" => Ok(Quality::High),
            _ => Err("expected low, medium or high".into()),
        }
    }
}

/// The instruction sets Embree's `isa=` accepts (and that cannot smuggle anything else into the
/// configuration string).
const ISAS: &[&str] = &["sse2", "sse4.2", "avx", "avx2", "avx512"];

impl EmbreeConfig {
    pub fn from_settings(mut s: Settings) -> Result<EmbreeConfig, EngineError> {
        let d = EmbreeConfig::default();
        let threads = s.get("threads", d.threads)?;
        let quality = s.get("quality", d.quality)?;
        let robust = s.get("robust", OnOff(d.robust))?.0;
        let compact = s.get("compact", d.compact)?;
        let isa: String = s.get("isa", String::new())?;
        let verbose = s.get("verbose", d.verbose)?;
        s.finish()?;
        let isa = if isa.is_empty() {
            None
        } else if ISAS.contains(&isa.as_str()) {
            Some(isa)
        } else {
            return Err(EngineError::BadValue {
                engine: "embree".into(),
                key: "isa".into(),
                value: isa,
                reason: format!("expected one of {}", ISAS.join(", ")),
            });
        };
        Ok(EmbreeConfig {
            threads,
            quality,
            robust,
            compact,
            isa,
            verbose,
        })
    }

    /// The device configuration string handed to `rtcNewDevice`.
    pub fn device_config(&self) -> String {
        let mut c = format!("threads={},verbose={}", self.threads, self.verbose);
        if let Some(isa) = &self.isa {
            c.push_str(",isa=");
            c.push_str(isa);
        }
        c
    }
}
