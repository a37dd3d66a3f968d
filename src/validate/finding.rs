//! Findings: what a check found, where, how bad, with the measured value and its limit.
//!
//! Entry points: [`Finding`], [`Severity`], [`AssetReport`], [`CHECKS`] (every check id with
//! its severity and a one-line description; SARIF rules and JUnit test cases come from it).

use serde::Serialize;
use sha2::{Digest, Sha256};

/// How bad a finding is (ordered: note < warning < error).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Note,
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(&self) -> &'static str {
        match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// Every check: id, default severity, what it means.
pub const CHECKS: &[(&str, Severity, &str)] = &[
    ("file.parse_error", Severity::Error, "The file is not valid XML, URDF or MJCF."),
    ("file.mesh_missing", Severity::Error, "A mesh file the asset names does not exist."),
    ("file.mesh_unreadable", Severity::Error, "A mesh file exists but cannot be read."),
    ("file.unsupported", Severity::Note, "Something in the file is not read (a geom type); it is left out of the checks."),
    ("asset.articulated", Severity::Warning, "Moving joints: an articulated robot, out of scope; its links are checked as one rigid part."),
    ("asset.free_object", Severity::Note, "An MJCF object model file (one body, no joint, no floor): checked as a free object on a ground plane."),
    ("inertia.positive_definite", Severity::Error, "Mass and principal moments of inertia must be positive."),
    ("inertia.triangle_inequality", Severity::Error, "Principal moments must satisfy A + B >= C (MuJoCo refuses the model otherwise)."),
    ("inertia.placeholder", Severity::Warning, "Authored principal moments are far from what the geometry and mass imply (a placeholder such as I = 1 kg·m²)."),
    ("inertia.density", Severity::Error, "Mass over collision volume is not a density any solid has (mass written in grams?)."),
    ("inertia.com_outside", Severity::Warning, "The authored centre of mass lies outside the convex hull of the body's geometry."),
    ("geometry.size", Severity::Warning, "Implausible size for a tabletop object (a mesh in millimetres?)."),
    ("geometry.concave_collision", Severity::Warning, "A concave collision mesh: MuJoCo and PhysX collide with its convex hull; the volume the hull adds."),
    ("geometry.hull_inside_body", Severity::Error, "Another body sits inside the convex hull engines use for a concave collision mesh (the lemon-in-bowl failure)."),
    ("geometry.gpu_hull_limit", Severity::Warning, "A convex collision shape over the PhysX GPU limit (64 vertices, 64 polygons): PhysX re-cooks it."),
    ("geometry.visual_collision_mismatch", Severity::Warning, "Visual and collision geometry disagree in extent."),
    ("contact.penetration", Severity::Error, "Two bodies' collision shapes interpenetrate at the initial pose."),
    ("contact.floor", Severity::Error, "A body's collision shapes go through the file's floor at the initial pose."),
    ("physics.skipped", Severity::Note, "The simulation did not run (invalid inertia or no dynamic body)."),
    ("physics.settle", Severity::Error, "A free body does not settle near its initial pose (drifts, turns, leaves its support)."),
    ("physics.rest", Severity::Error, "A free body does not stay at rest after settling (creeps, turns, penetrates)."),
];

/// The default severity of a check id.
pub fn severity_of(check: &str) -> Severity {
    CHECKS
        .iter()
        .find(|c| c.0 == check)
        .map(|c| c.1)
        .unwrap_or(Severity::Warning)
}

/// One finding.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    pub check: String,
    pub severity: Severity,
    /// Body, link or geom name (or `a/b` for a pair).
    pub subject: String,
    /// The file that defines the subject (an included file when that is where it is).
    pub file: String,
    /// 1-based line of the element that defines the subject (0 when unknown).
    pub line: usize,
    pub message: String,
    /// The measured value and its limit, in the check's unit (stated in the message).
    pub value: Option<f64>,
    pub limit: Option<f64>,
    /// Stable key for baselines: the check, the subject and the asset file, not the line.
    pub fingerprint: String,
    /// Listed in the baseline: reported, but does not fail the run.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub baselined: bool,
}

impl Finding {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        check: &str,
        subject: &str,
        file: &str,
        line: usize,
        message: String,
        value: Option<f64>,
        limit: Option<f64>,
        asset: &str,
    ) -> Finding {
        Finding {
            check: check.to_string(),
            severity: severity_of(check),
            subject: subject.to_string(),
            file: file.to_string(),
            line,
            message,
            value,
            limit,
            fingerprint: fingerprint(check, subject, asset),
            baselined: false,
        }
    }
}

/// sha256 of check, subject and asset path (forward slashes), first 16 bytes in hex.
pub fn fingerprint(check: &str, subject: &str, asset: &str) -> String {
    let mut h = Sha256::new();
    for part in [check, subject, &asset.replace('\\', "/")] {
        h.update(part.as_bytes());
        h.update([0u8]);
    }
    h.finalize()[..16]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The verdict on one asset.
#[derive(Clone, Debug, Serialize)]
pub struct AssetReport {
    /// The asset's path as given (or as found under a folder).
    pub file: String,
    /// `urdf`, `mjcf`, `scene` or `unreadable`.
    pub format: String,
    pub bodies: usize,
    /// Check ids that ran on this asset (JUnit test cases).
    pub checks: Vec<String>,
    pub findings: Vec<Finding>,
}

impl AssetReport {
    /// Findings at or above `level` that are not baselined.
    pub fn failing(&self, level: Severity) -> usize {
        self.findings
            .iter()
            .filter(|f| f.severity >= level && !f.baselined)
            .count()
    }
    pub fn count(&self, s: Severity) -> usize {
        self.findings.iter().filter(|f| f.severity == s).count()
    }
}
