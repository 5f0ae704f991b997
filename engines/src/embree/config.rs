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
    pub api: Api,
}

/// Which of Embree's query calls a batch goes through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Api {
    /// `rtcIntersect1` / `rtcOccluded1`, ray by ray.
    Single,
    /// `rtcIntersect8` / `rtcOccluded8`: consecutive rays of a batch 8 at a time (Embree's
    /// packet traversal, the fair partner of a packet tracer).
    Packet8,
    /// `rtcIntersect16` / `rtcOccluded16`, 16 at a time.
    Packet16,
}

impl std::str::FromStr for Api {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "single" | "1" => Ok(Api::Single),
            "packet8" | "8" => Ok(Api::Packet8),
            "packet16" | "16" => Ok(Api::Packet16),
            _ => Err("expected single, packet8 or packet16".into()),
        }
    }
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
            api: Api::Single,
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
        let api = s.get("api", d.api)?;
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
            api,
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
