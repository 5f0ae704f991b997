//! Published figures, deserialised from `data/published/<id>.json` (compiled in) into typed structs
//! that carry their source. The file's whole text is echoed into the result JSON as it is, so a report
//! shows exactly what it was compared with.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Where a published figure comes from: document, and where in it.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
pub struct Source {
    pub document: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub section: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sections: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl Source {
    /// "document; sections" for a report's first paragraph.
    pub fn cite(&self) -> String {
        let place = self
            .sections
            .as_deref()
            .or(self.section.as_deref())
            .or(self.table.as_deref());
        match place {
            Some(p) => format!("{}; {p}", self.document),
            None => self.document.clone(),
        }
    }
}

/// A claim as transcribed in a published file (`claims` arrays).
#[derive(Clone, Debug, Deserialize, Serialize)]
pub struct PublishedClaim {
    pub id: String,
    #[serde(default)]
    pub source: String,
    pub claim: String,
    #[serde(default)]
    pub check: String,
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// `text` (a `data/published/<id>.json` compiled in) as `T`, and as raw JSON for the report. The
/// files are part of the build: a file that does not parse is a broken build, caught by the tests.
pub fn load<T: DeserializeOwned>(id: &str, text: &str) -> (T, serde_json::Value) {
    let typed = serde_json::from_str(text)
        .unwrap_or_else(|e| panic!("data/published/{id}.json does not match its type: {e}"));
    let raw = serde_json::from_str(text).expect("published JSON parses");
    (typed, raw)
}

/// The claim with this id, from a published claim list.
pub fn claim<'a>(claims: &'a [PublishedClaim], id: &str) -> &'a PublishedClaim {
    claims
        .iter()
        .find(|c| c.id == id)
        .unwrap_or_else(|| panic!("no published claim '{id}'"))
}
