//! The XML database loader, as `robosim check` and `robosim run` use it.
//!
//! The input is the three files of a database separated by a 0xFF byte (which never occurs
//! in UTF-8): `bodies.xml 0xFF robots.xml 0xFF scenes.xml`. A file left out (fewer
//! separators) is absent from the folder. What must hold, whatever the bytes:
//!
//! - loading never panics: whatever is wrong is a problem in the list, and every problem
//!   prints as one line (the CLI's promise);
//! - every scene either builds a `Simulation` or gives a `BuildError`, and one that builds
//!   keeps every number of its trace record finite for 20 steps;
//! - saving the loaded database to another folder and loading that gives the same model,
//!   and the saved files read without a single reading problem.

#![no_main]

use libfuzzer_sys::fuzz_target;
use robosim::db::{Database, FileKind, Overwrite};
use robosim::sim::Simulation;
use robosim::sim::trace::Record;
use std::path::Path;

const SEPARATOR: u8 = 0xFF;
const STEPS: usize = 20;

/// A fresh folder, in memory where the system has one (saving fsyncs every file).
fn scratch_dir() -> tempfile::TempDir {
    let shm = Path::new("/dev/shm");
    if shm.is_dir() {
        tempfile::tempdir_in(shm).expect("a folder in /dev/shm")
    } else {
        tempfile::tempdir().expect("a temporary folder")
    }
}

fn assert_finite_record(record: &Record, scene: &str) {
    let step = record.step;
    let finite = |what: &str, id: &str, v: f64| {
        assert!(
            v.is_finite(),
            "scene {scene:?}, step {step}: {id} {what} = {v} is not finite"
        );
    };
    finite("time", "", record.time);
    for b in &record.bodies {
        for (what, v) in [
            ("x", b.x),
            ("y", b.y),
            ("angle", b.angle),
            ("vx", b.vx),
            ("vy", b.vy),
            ("omega", b.omega),
        ] {
            finite(what, &b.id, v);
        }
    }
    for j in &record.joints {
        finite("gap", &j.id, j.gap);
    }
    finite("kinetic energy", "", record.energy.kinetic);
    finite("potential energy", "", record.energy.potential);
}

fuzz_target!(|data: &[u8]| {
    let dir = scratch_dir();
    for (kind, part) in FileKind::ALL
        .iter()
        .zip(data.splitn(3, |&b| b == SEPARATOR))
    {
        std::fs::write(dir.path().join(kind.file_name()), part).expect("writing a file");
    }

    let (mut db, problems) = Database::load(dir.path());
    for p in &problems {
        let line = p.to_string();
        assert!(
            !line.contains(['\n', '\r']),
            "a problem of more than one line: {line:?}"
        );
    }

    // Every scene, as the editor runs it (the CLI's `run` also refuses a database with
    // errors; the editor simulates whatever builds).
    let names: Vec<String> = db.model.scenes.iter().map(|s| s.name.clone()).collect();
    for name in &names {
        let Ok(mut sim) = Simulation::new(&db.model, name, None, None) else {
            continue;
        };
        assert_finite_record(&Record::of(&sim), name);
        for _ in 0..STEPS {
            sim.step();
            assert_finite_record(&Record::of(&sim), name);
        }
    }

    // Save to another folder and load again: the same records, read without a problem.
    let copy = scratch_dir();
    let model = db.model.clone();
    db.save_to(copy.path(), Overwrite::Never)
        .expect("saving to a new, empty folder");
    let (again, again_problems) = Database::load(copy.path());
    assert_eq!(
        again.model, model,
        "the model changed through save and load"
    );
    let checked = again.check();
    assert_eq!(
        again_problems, checked,
        "a saved file gave reading problems (beyond the model's own check)"
    );
});
