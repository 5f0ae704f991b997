//! What every reproduction row says: the claim it tests, published beside measured, how they compare,
//! the verdict, and the fidelity label (docs/concepts.md): a claim is judged
//! only on the algorithm, setting and scene it was made for, and a row says when it was not.

use serde::Serialize;

/// How faithfully a row reproduces its claim.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Fidelity {
    /// Same algorithm, same settings, same scene as the source.
    #[serde(rename = "faithful")]
    Faithful,
    /// A named stand-in (scene, machine model, setting); the claim's note says which and why.
    #[serde(rename = "substituted")]
    Substituted,
    /// A model in place of a measurement (e.g. the paging model of thrashing).
    #[serde(rename = "model")]
    Model,
    /// Cannot be reproduced here; the note says why.
    #[serde(rename = "not reproducible")]
    NotReproducible,
}

impl Fidelity {
    pub const ALL: [Fidelity; 4] = [
        Fidelity::Faithful,
        Fidelity::Substituted,
        Fidelity::Model,
        Fidelity::NotReproducible,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Fidelity::Faithful => "faithful",
            Fidelity::Substituted => "substituted",
            Fidelity::Model => "model",
            Fidelity::NotReproducible => "not reproducible",
        }
    }
}

/// One claim a table tests, declared in its file: a key its rows name, what the source says, and the
/// fidelity with which we test it (with the reason when it is not `faithful`).
#[derive(Clone, Copy, Debug)]
pub struct Claim {
    pub key: &'static str,
    pub fidelity: Fidelity,
    pub why: &'static str,
}

/// Where a measured figure lies against a published range `[lo, hi]`, by `names` (below, inside,
/// above), with a word on its 95 % interval when it reaches across the bound the verdict turns
/// on. Whether the figure is `inside` is the caller's to say (a check may round as the source
/// printed); the verdict rests on it, the note says how far to trust it.
pub fn range_note(
    inside: bool,
    v: f64,
    interval: Option<[f64; 2]>,
    (lo, hi): (f64, f64),
    names: [&str; 3],
) -> String {
    let across = interval.is_some_and(|[a, b]| {
        if inside {
            a < lo || b > hi
        } else {
            b >= lo && a <= hi
        }
    });
    let name = match (inside, v < lo) {
        (true, _) => names[1],
        (false, true) => names[0],
        (false, false) => names[2],
    };
    match (across, inside) {
        (false, _) => name.to_string(),
        (true, true) => format!("{name} (its interval reaches past a bound)"),
        (true, false) => format!("{name} (its interval reaches into it)"),
    }
}

/// How a published figure is compared with a measured one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Two counts that must be equal.
    Count,
    /// A ratio, within a stated tolerance or on one side of a bound.
    Ratio,
    /// An ordering or a pattern that must hold.
    Ordering,
    /// A value inside a published range.
    Range,
    /// The shape of a curve (growth, decay, a knee).
    Shape,
}

/// The verdict of one row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Verdict {
    #[serde(rename = "holds")]
    Holds,
    #[serde(rename = "does not hold")]
    Fails,
    /// Measured and shown, with no pass/fail (e.g. a figure the source gives without a bound).
    #[serde(rename = "shown")]
    Shown,
    #[serde(rename = "not measured")]
    NotMeasured,
}

impl Verdict {
    pub fn of(holds: bool) -> Verdict {
        if holds {
            Verdict::Holds
        } else {
            Verdict::Fails
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Holds => "holds",
            Verdict::Fails => "does not hold",
            Verdict::Shown => "shown",
            Verdict::NotMeasured => "not measured",
        }
    }
}

/// One comparison row: the typed result every table returns, whatever else it measured.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The key of a [`Claim`] its table declares.
    pub claim: &'static str,
    /// What it was measured on: a scene, a configuration, or "-" for the whole table.
    pub subject: String,
    pub published: String,
    pub measured: String,
    pub kind: Kind,
    pub verdict: Verdict,
    /// Filled in by the writer from the claim's declaration (a row may narrow it, never widen it).
    pub fidelity: Option<Fidelity>,
    pub note: String,
}

impl Row {
    pub fn new(
        claim: &'static str,
        subject: impl Into<String>,
        published: impl Into<String>,
        measured: impl Into<String>,
        kind: Kind,
        verdict: Verdict,
    ) -> Row {
        Row {
            claim,
            subject: subject.into(),
            published: published.into(),
            measured: measured.into(),
            kind,
            verdict,
            fidelity: None,
            note: String::new(),
        }
    }
    /// This row's own fidelity, where it is lower than its claim's (e.g. one scene substituted).
    pub fn with_fidelity(mut self, f: Fidelity, note: impl Into<String>) -> Row {
        self.fidelity = Some(f);
        self.note = note.into();
        self
    }
    pub fn with_note(mut self, note: impl Into<String>) -> Row {
        self.note = note.into();
        self
    }
}
