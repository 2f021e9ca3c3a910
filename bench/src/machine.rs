//! What a report names about its run: the machine, the load, the code's commit, the
//! peers' versions and builds, the date.

use std::time::{SystemTime, UNIX_EPOCH};

/// The 1-, 5- and 15-minute load averages: other work on the machine slows every engine.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

/// The code measured: the repository's commit, and whether pe's or the bench's sources
/// differ from it (a run of work in progress), from `git` at the start of the run.
pub fn code_version() -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let git = |args: &[&str]| {
        let out = std::process::Command::new("git")
            .arg("-C")
            .arg(root)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())?;
        String::from_utf8(out.stdout).ok()
    };
    let Some(commit) = git(&["rev-parse", "--short", "HEAD"]) else {
        return "code: unknown (no git repository)".into();
    };
    let sources = [
        "physics",
        "bench/src",
        "bench/Cargo.toml",
        "bench/Cargo.lock",
        "bench/.cargo",
    ];
    let status = git(&[&["status", "--porcelain", "--"][..], &sources[..]].concat());
    let changed = match status.as_deref() {
        Some("") => "",
        Some(_) => ", with uncommitted changes to pe or the bench",
        None => ", changes unknown",
    };
    format!("code of commit {}{changed}", commit.trim())
}

/// CPU model and logical core count, from /proc/cpuinfo (Linux).
pub fn machine() -> String {
    let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
        return "unknown (no /proc/cpuinfo)".into();
    };
    // `name: value`, as /proc/cpuinfo lists its fields ("model" is not "model name").
    let field = |name: &str| {
        info.lines()
            .find_map(|l| l.strip_prefix(name)?.trim_start().strip_prefix(':'))
            .map(str::trim)
    };
    let model = field("model name").unwrap_or("unknown CPU");
    let cores = info.lines().filter(|l| l.starts_with("processor")).count();
    // Same-model names cover several generations (an EPYC with AVX-512 or without), and
    // pe's batches run as wide as the processor allows.
    format!(
        "{model} (family {}, model {}), {cores} logical cores; pe's soft-step batches in {}",
        field("cpu family").unwrap_or("?"),
        field("model").unwrap_or("?"),
        pe::lane_path_name()
    )
}

/// The flags cc added after boxdd's own when it compiled Box2D's C sources (`CFLAGS`, set
/// by bench/.cargo/config.toml unless the shell sets it): the later flags win.
const BOX2D_CFLAGS: Option<&str> = option_env!("CFLAGS");

/// How the peers were built (bench/Cargo.toml, feature `fastest-peers`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PeerBuild {
    /// Box2D v3 with `BOX2D_AVX2`, rapier2d with eight solver lanes: each one's fastest
    /// on a processor with AVX2.
    Fastest,
    /// Both as their default features build them: four f32 lanes in SSE2.
    Default,
}

impl PeerBuild {
    pub const CURRENT: Self = if cfg!(feature = "fastest-peers") {
        Self::Fastest
    } else {
        Self::Default
    };

    pub fn rapier2d(self) -> &'static str {
        match self {
            Self::Fastest => "feature `simd8`: eight solver lanes, in AVX2",
            Self::Default => "default features: four solver lanes",
        }
    }

    /// Box2D's commit, its lanes and its C flags.
    pub fn box2d(self) -> String {
        let lanes = match self {
            Self::Fastest => "`BOX2D_AVX2`: eight lanes in AVX2",
            Self::Default => "boxdd's default: four lanes in SSE2",
        };
        let flags = match BOX2D_CFLAGS.map(str::trim) {
            Some(f) if !f.is_empty() => format!("C compiled with boxdd's flags and then `{f}`"),
            _ => "C compiled with boxdd's flags (-O2, asserts in)".into(),
        };
        let commit = boxdd_sys::UPSTREAM_SHA.get(..7).unwrap_or("unknown");
        format!("Box2D's sources of commit {commit}, {lanes}, {flags}")
    }

    /// Whether this processor runs the build: Box2D's AVX2 build would stop at its
    /// first vector instruction on one without.
    pub fn runs_here(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self == Self::Fastest {
            return std::arch::is_x86_feature_detected!("avx2");
        }
        true
    }
}

/// The rapier2d version actually built, from this crate's lock file.
pub fn rapier_version() -> &'static str {
    locked_version("rapier2d")
}

/// A dependency's version as this crate's lock file records it.
pub fn locked_version(name: &str) -> &'static str {
    let lock = include_str!("../Cargo.lock");
    let wanted = format!("name = \"{name}\"");
    lock.split("[[package]]")
        .find(|p| p.lines().any(|l| l.trim() == wanted))
        .and_then(|p| p.lines().find_map(|l| l.strip_prefix("version = ")))
        .map_or("(unknown version)", |v| v.trim_matches('"'))
}

/// Today's date (UTC) as YYYY-MM-DD, without a date library: days since 1970 to the
/// proleptic Gregorian calendar (H. Hinnant's `civil_from_days`).
pub fn today() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bench runs from its repository: results.md names the commit it measured, and
    /// says so when pe's or the bench's sources differ from it.
    #[test]
    fn the_code_measured_is_named_by_its_commit() {
        let code = code_version();
        let commit = code.strip_prefix("code of commit ").expect(&code);
        let hash = commit.split(',').next().unwrap();
        assert!(
            hash.len() >= 7 && hash.chars().all(|c| c.is_ascii_hexdigit()),
            "{code}"
        );
        let rest = &commit[hash.len()..];
        assert!(
            ["", ", with uncommitted changes to pe or the bench"].contains(&rest),
            "{code}"
        );
    }

    #[test]
    fn civil_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(20_454), (2026, 1, 1));
    }

    /// results.md names the Box2D commit boxdd built and the C flags it got.
    #[test]
    fn the_box2d_build_names_its_commit_and_flags() {
        let build = PeerBuild::CURRENT.box2d();
        let commit = build
            .strip_prefix("Box2D's sources of commit ")
            .expect(&build);
        assert!(
            commit.chars().take(7).all(|c| c.is_ascii_hexdigit()),
            "{build}"
        );
        assert!(build.contains("C compiled with boxdd's flags"), "{build}");
    }

    #[test]
    fn the_lock_file_names_rapier() {
        assert!(rapier_version().starts_with("0."));
    }
}
