//! Saving under failure: the three files are saved as one (all new or all old, whatever
//! step fails), keep their permissions and symbolic links, and a folder that cannot be
//! synced after every file is in place does not make the next save refuse.

use robosim::db::{Database, FileKind, Overwrite, SaveError, SaveStep};
use std::path::Path;

/// A copy of the default database in a fresh folder.
fn copy_of_data() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for kind in FileKind::ALL {
        std::fs::copy(
            Path::new("data").join(kind.file_name()),
            dir.path().join(kind.file_name()),
        )
        .unwrap();
    }
    dir
}

fn contents(dir: &Path) -> Vec<Vec<u8>> {
    FileKind::ALL
        .iter()
        .map(|k| std::fs::read(dir.join(k.file_name())).unwrap())
        .collect()
}

fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// An edit to every file, so that a save writes all three.
fn edit_everything(db: &mut Database) {
    db.model.bodies[0].density *= 2.0;
    db.model.robots[0].bodies[0].placement.x += 1.0;
    db.model.scenes[0].friction = 0.25;
}

/// Every step of a save, as a save that fails none of them takes them.
fn steps_of_a_save() -> Vec<SaveStep> {
    let dir = copy_of_data();
    let (mut db, _) = Database::load(dir.path());
    edit_everything(&mut db);
    let mut steps = Vec::new();
    db.save_with(dir.path(), Overwrite::Never, |step| {
        steps.push(step);
        Ok(())
    })
    .unwrap();
    steps
}

#[test]
fn a_save_that_fails_at_any_step_leaves_all_the_old_files_or_all_the_new() {
    let steps = steps_of_a_save();
    // Three temporaries, three backups, three renames, the folder.
    assert_eq!(steps.len(), 10, "{steps:?}");
    let new = {
        let dir = copy_of_data();
        let (mut db, _) = Database::load(dir.path());
        edit_everything(&mut db);
        db.save(Overwrite::Never).unwrap();
        contents(dir.path())
    };
    for (k, failing) in steps.iter().enumerate() {
        let dir = copy_of_data();
        let old = contents(dir.path());
        let (mut db, _) = Database::load(dir.path());
        edit_everything(&mut db);
        let mut taken = 0;
        let result = db.save_with(dir.path(), Overwrite::Never, |step| {
            taken += 1;
            if taken == k + 1 {
                assert_eq!(step, *failing);
                Err(std::io::Error::other("the disk is full"))
            } else {
                Ok(())
            }
        });
        let now = contents(dir.path());
        if *failing == SaveStep::SyncFolder {
            assert!(
                matches!(result, Err(SaveError::NotDurable { .. })),
                "{result:?}"
            );
            assert_eq!(now, new, "failing {failing:?}: every file is in place");
            // The save did happen: the next one has nothing to refuse.
            db.model.bodies[0].cor = 0.5;
            db.save(Overwrite::Never).unwrap();
        } else {
            assert!(matches!(result, Err(SaveError::Io { .. })), "{result:?}");
            assert_eq!(now, old, "failing {failing:?}: every old file is back");
            // And a save that completes writes what was asked.
            db.save(Overwrite::Never).unwrap();
            assert_eq!(contents(dir.path()), new, "after failing {failing:?}");
        }
        assert_eq!(
            names(dir.path()),
            ["bodies.xml", "robots.xml", "scenes.xml"],
            "failing {failing:?}: nothing left behind"
        );
    }
}

#[cfg(unix)]
#[test]
fn a_saved_file_keeps_its_permissions_and_its_symbolic_link() {
    use std::os::unix::fs::PermissionsExt;
    let dir = copy_of_data();
    let elsewhere = tempfile::tempdir().unwrap();
    let real_bodies = elsewhere.path().join("shared-bodies.xml");
    std::fs::rename(dir.path().join("bodies.xml"), &real_bodies).unwrap();
    std::os::unix::fs::symlink(&real_bodies, dir.path().join("bodies.xml")).unwrap();
    let robots = dir.path().join("robots.xml");
    std::fs::set_permissions(&robots, std::fs::Permissions::from_mode(0o640)).unwrap();
    std::fs::set_permissions(&real_bodies, std::fs::Permissions::from_mode(0o664)).unwrap();

    let (mut db, _) = Database::load(dir.path());
    edit_everything(&mut db);
    db.save(Overwrite::Never).unwrap();

    let link = std::fs::symlink_metadata(dir.path().join("bodies.xml")).unwrap();
    assert!(link.file_type().is_symlink(), "bodies.xml is still a link");
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&real_bodies), 0o664);
    assert_eq!(mode(&robots), 0o640);
    let (again, _) = Database::load(dir.path());
    assert_eq!(
        again.model, db.model,
        "the link's target holds the saved bodies"
    );
    // A new file is made as the user's files are, not private to them.
    let fresh = tempfile::tempdir().unwrap();
    Database::new(db.model.clone())
        .save_to(fresh.path(), Overwrite::Never)
        .unwrap();
    let scenes_mode = mode(&fresh.path().join("scenes.xml"));
    assert_ne!(
        scenes_mode & 0o044,
        0,
        "readable by others: {scenes_mode:o}"
    );
}

/// A save writes only the files whose records changed, and in them every unchanged record
/// as it was, byte for byte: the thesis's `1e+006`, a leading space in a name, odd
/// spacing. Only the edited record is written anew.
#[test]
fn a_save_writes_only_what_changed_and_unchanged_records_as_they_were() {
    let dir = tempfile::tempdir().unwrap();
    let bodies = "<?xml version=\"1.0\"?>\n<bodies>\n  <body name=\"obdelnik\" density=\"1\" cor=\"0.2\">\n    <vertex x=\"20\" y=\"-10\"/>\n    <vertex x=\"20\" y=\"10\"/>\n    <vertex x=\"-20\" y=\"10\"/>\n    <vertex x=\"-20\" y=\"-10\"/>\n  </body>\n  <body   name=\"floor\"  density=\"0\" cor=\"2e-001\">\n      <vertex x=\"-300\" y=\"-10\"/><vertex x=\"300\" y=\"-10\"/>\n      <vertex x=\"300\" y=\"10\"/><vertex x=\"-300\" y=\"10\"/>\n  </body>\n</bodies>\n";
    let robots = "<robots>\n  <robot name=\"housenka\">\n    <body alias=\"h_0\" source=\"obdelnik\" x=\"-33\" y=\"0\" orientation=\"0\">\n      <force time0=\"0\" time1=\"1000\" angular=\"0.3\" startTorque=\"1e+006\"\n        maxTorque=\"2e+006\" increase=\"0.001\"/>\n    </body>\n    <body alias=\"h_1\" source=\"obdelnik\" x=\"-1\" y=\"0\" orientation=\"0\">\n    </body>\n    <joint bodyA=\"h_0\" bodyB=\"h_1\" anchorAx=\"16\" anchorAy=\"0\"/>\n  </robot>\n</robots>\n";
    let scenes = "<scenes>\n  <scene name=\"testovaci scena\" gravitation=\"9.1\" friction=\"0.7\" >\n    <robot source=\" housenka\" x=\"368.25\" y=\"132.334\" orientation=\"0\"/>\n    <body alias=\"floor\" source=\"floor\" x=\"300\" y=\"300\" orientation=\"0\"/>\n  </scene>\n</scenes>\n";
    for (kind, text) in [
        (FileKind::Bodies, bodies),
        (FileKind::Robots, robots),
        (FileKind::Scenes, scenes),
    ] {
        std::fs::write(dir.path().join(kind.file_name()), text).unwrap();
    }
    let (mut db, problems) = Database::load(dir.path());
    assert!(problems.iter().all(|p| !p.is_error()), "{problems:?}");
    db.model.bodies[0].density = 2.0;
    let mut written = Vec::new();
    db.save_with(dir.path(), Overwrite::Never, |step| {
        if let SaveStep::WriteTemporary(kind) = step {
            written.push(kind);
        }
        Ok(())
    })
    .unwrap();
    assert_eq!(
        written,
        [FileKind::Bodies],
        "only the edited file is written"
    );
    let read = |kind: FileKind| std::fs::read_to_string(dir.path().join(kind.file_name())).unwrap();
    assert_eq!(read(FileKind::Robots), robots);
    assert_eq!(read(FileKind::Scenes), scenes);
    let saved = read(FileKind::Bodies);
    let floor = &bodies
        [bodies.find("<body   name=\"floor\"").unwrap()..bodies.rfind("</body>").unwrap() + 7];
    assert!(saved.contains(floor), "the floor as it was:\n{saved}");
    assert!(saved.contains("density=\"2\""), "{saved}");
    // A second save of the same edit writes nothing at all.
    let mut written = Vec::new();
    db.save_with(dir.path(), Overwrite::Never, |step| {
        written.push(step);
        Ok(())
    })
    .unwrap();
    assert!(written.is_empty(), "{written:?}");
    let (again, _) = Database::load(dir.path());
    assert_eq!(again.model, db.model);
}

/// What reading ignored with a warning (an unknown element, stray text, a CDATA section)
/// is not kept by a save, as the warning says: its record is written afresh, and the saved
/// file reads without a warning. Clean records beside it stay byte for byte.
#[test]
fn a_record_with_ignored_content_is_saved_without_it() {
    let dir = tempfile::tempdir().unwrap();
    let clean = "<body name=\"clean\" density=\"1e+000\" cor=\"0\">\n    <vertex x=\"0\" y=\"0\"/><vertex x=\"1\" y=\"0\"/><vertex x=\"0\" y=\"1\"/>\n  </body>";
    let bodies = format!(
        "<bodies>\n  {clean}\n  <body name=\"odd\" density=\"1\" cor=\"0\">\n    <versex x=\"5\" y=\"5\"/>stray<![CDATA[x]]>\n    <vertex x=\"0\" y=\"0\"/><vertex x=\"2\" y=\"0\"/><vertex x=\"0\" y=\"2\"/>\n  </body>\n</bodies>\n"
    );
    std::fs::write(dir.path().join("bodies.xml"), &bodies).unwrap();
    let (mut db, problems) = Database::load(dir.path());
    let warnings: Vec<_> = problems.iter().filter(|p| !p.is_error()).collect();
    assert_eq!(warnings.len(), 3, "{problems:#?}");
    let copy = tempfile::tempdir().unwrap();
    db.save_to(copy.path(), Overwrite::Never).unwrap();
    let saved = std::fs::read_to_string(copy.path().join("bodies.xml")).unwrap();
    assert!(
        saved.contains(clean),
        "the clean record as it was:\n{saved}"
    );
    for ignored in ["versex", "stray", "CDATA"] {
        assert!(!saved.contains(ignored), "{ignored} was kept:\n{saved}");
    }
    let (again, problems) = Database::load(copy.path());
    assert!(problems.is_empty(), "{problems:#?}");
    assert_eq!(again.model, db.model);
}

/// A file that is there but cannot be read (here a folder named bodies.xml; also a file
/// over the size limit, or one without permission) loads as an empty collection with an
/// error, and a save never writes over it: an edit elsewhere saves the other files, and an
/// edit to its own collection is refused unless the user accepts the loss.
#[test]
fn a_file_that_could_not_be_read_is_never_written_over() {
    let dir = copy_of_data();
    let bodies = dir.path().join(FileKind::Bodies.file_name());
    std::fs::remove_file(&bodies).unwrap();
    std::fs::create_dir(&bodies).unwrap();
    std::fs::write(bodies.join("keep"), "the user's").unwrap();
    let (mut db, problems) = Database::load(dir.path());
    assert!(
        problems
            .iter()
            .any(|p| p.file.ends_with("bodies.xml") && p.message.contains("cannot read")),
        "{problems:#?}"
    );
    assert!(db.model.bodies.is_empty());
    db.model.scenes[0].friction = 0.25;
    db.save(Overwrite::Never).unwrap();
    assert!(
        bodies.join("keep").exists(),
        "the unreadable file was left alone"
    );
    assert_eq!(Database::load(dir.path()).0.model.scenes[0].friction, 0.25);

    db.model
        .bodies
        .push(db.model.bodies.first().cloned().unwrap_or_default());
    assert!(matches!(
        db.save(Overwrite::Never),
        Err(SaveError::WouldDropRecords(path)) if path == bodies
    ));
    assert!(bodies.join("keep").exists());
}
