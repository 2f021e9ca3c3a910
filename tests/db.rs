//! The XML database (issue 5): the thesis's examples, round trips, a corpus of broken files,
//! atomic and careful saving, referential integrity.

use proptest::prelude::*;
use robosim::db::{
    Database, Delete, EditError, FileKind, Overwrite, Problem, SaveError, Severity, User,
};
use robosim::model::{
    BodyDef, JointDef, Model, Placement, Robot, RobotBody, Scene, SceneRobot, same_name,
};
use std::path::Path;

const BOX_BODIES: &str = r#"<bodies>
  <body name="box" density="1" cor="0.2">
    <vertex x="-10" y="-10"/>
    <vertex x="10" y="-10"/>
    <vertex x="10" y="10"/>
    <vertex x="-10" y="10"/>
  </body>
</bodies>
"#;

fn write(dir: &Path, kind: FileKind, text: impl AsRef<[u8]>) {
    std::fs::write(dir.join(kind.file_name()), text).unwrap();
}

fn load(files: &[(FileKind, &[u8])]) -> (Database, Vec<Problem>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    for (kind, text) in files {
        write(dir.path(), *kind, text);
    }
    let (db, problems) = Database::load(dir.path());
    (db, problems, dir)
}

#[test]
fn the_spec_examples_parse_to_their_values() {
    let (db, problems) = Database::embedded();
    assert!(
        problems.is_empty(),
        "the default database is clean: {problems:#?}"
    );
    let m = &db.model;
    let obdelnik = m.body("obdelnik").unwrap();
    assert_eq!((obdelnik.density, obdelnik.cor), (1.0, 0.2));
    assert_eq!(
        obdelnik.vertices,
        vec![[20.0, -10.0], [20.0, 10.0], [-20.0, 10.0], [-20.0, -10.0]]
    );
    let housenka = m.robot("housenka").unwrap();
    let aliases: Vec<_> = housenka
        .bodies
        .iter()
        .map(|b| b.placement.alias.as_str())
        .collect();
    assert_eq!(aliases, ["h_0", "h_1", "h_2"]);
    assert_eq!(housenka.bodies[0].placement.x, -33.0);
    let force = &housenka.bodies[0].motors[0];
    assert_eq!((force.time0, force.time1, force.angular), (0, 1000, 0.3));
    assert_eq!(
        (force.start_torque, force.max_torque, force.increase),
        (1e6, 2e6, 0.001)
    );
    assert!(housenka.bodies[1].motors.is_empty());
    let j = &housenka.joints[1];
    assert_eq!(
        (
            j.body_a.as_str(),
            j.body_b.as_str(),
            j.anchor_ax,
            j.anchor_ay
        ),
        ("h_1", "h_2", 17.0, -1.0)
    );
    // thesis §4.3.2: the joint points are the centres of the overlaps.
    assert_eq!(
        housenka.joints[0].point(&housenka.bodies[0].placement),
        [-17.0, 0.0]
    );
    assert_eq!(j.point(&housenka.bodies[1].placement), [16.0, -1.0]);
    let scene = m.scene("testovaci scena").unwrap();
    assert_eq!(
        (scene.gravitation, scene.friction, scene.timestep),
        (9.1, 0.7, None)
    );
    assert_eq!(scene.robots[0].source, " housenka", "kept as written");
    assert!(
        m.robot(&scene.robots[0].source).is_some(),
        "and resolved trimmed"
    );
    assert_eq!((scene.robots[0].x, scene.robots[0].y), (368.25, 132.334));
    assert_eq!(scene.bodies[0].alias, "o_1");
}

#[test]
fn the_default_database_on_disk_matches_the_embedded_one() {
    let (on_disk, problems) = Database::load(Path::new("data"));
    assert!(problems.is_empty(), "{problems:#?}");
    assert_eq!(on_disk.model, Database::embedded().0.model);
}

fn name() -> impl Strategy<Value = String> {
    "[a-zA-Z_][a-zA-Z0-9 _&<>'\"#-]{0,12}"
        .prop_map(|s| s.trim().to_string())
        .prop_filter("non-empty", |s| !s.is_empty())
}

/// Any finite f64, including awkward ones (subnormals, -0, huge, long fractions).
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3f64..1e3,
        any::<f64>().prop_filter("finite", |v| v.is_finite()),
        Just(-0.0),
        Just(1e-320),
        Just(0.1 + 0.2),
    ]
}

fn placement() -> impl Strategy<Value = Placement> {
    (name(), name(), number(), number(), number(), velocity()).prop_map(
        |(alias, source, x, y, orientation, velocity)| Placement {
            alias,
            source,
            x,
            y,
            orientation,
            velocity,
            ..Placement::default()
        },
    )
}

/// At rest half the time (no attributes written), else any numbers.
fn velocity() -> impl Strategy<Value = robosim::model::StartVelocity> {
    prop_oneof![
        Just(robosim::model::StartVelocity::default()),
        (number(), number(), number())
            .prop_map(|(vx, vy, omega)| { robosim::model::StartVelocity { vx, vy, omega } }),
    ]
}

fn model() -> impl Strategy<Value = Model> {
    let body = (
        name(),
        number(),
        number(),
        prop::option::of(number()),
        prop::collection::vec((number(), number()), 0..5),
    )
        .prop_map(|(name, density, cor, friction, vertices)| BodyDef {
            name,
            density,
            cor,
            friction,
            vertices: vertices.into_iter().map(|(x, y)| [x, y]).collect(),
            ..BodyDef::default()
        });
    let motor = (
        0u64..10_000,
        0u64..10_000,
        number(),
        number(),
        number(),
        number(),
    )
        .prop_map(|(t0, t1, a, s, m, i)| robosim::model::BodyMotorDef {
            time0: t0,
            time1: t1,
            angular: a,
            start_torque: s,
            max_torque: m,
            increase: i,
            ..Default::default()
        });
    let joint_motor = (0u64..10_000, 0u64..10_000, number(), number(), 0u64..100).prop_map(
        |(t0, t1, a, m, period)| robosim::model::JointMotorDef {
            time0: t0,
            time1: t1,
            angular: a,
            max_torque: m,
            period,
            ..Default::default()
        },
    );
    let joint = (
        name(),
        name(),
        number(),
        number(),
        any::<bool>(),
        prop::option::of(joint_motor),
        prop::option::of((number(), number(), number())),
        (prop::option::of(number()), prop::option::of(number())),
    )
        .prop_map(
            |(a, b, ax, ay, collide, motor, spring, (lower_angle, upper_angle))| JointDef {
                body_a: a,
                body_b: b,
                anchor_ax: ax,
                anchor_ay: ay,
                collide,
                motor,
                lower_angle,
                upper_angle,
                spring: spring.map(|(stiffness, damping, rest_angle)| {
                    robosim::model::JointSpringDef {
                        stiffness,
                        damping,
                        rest_angle,
                    }
                }),
                ..JointDef::default()
            },
        );
    let robot = (
        name(),
        prop::collection::vec((placement(), prop::collection::vec(motor, 0..2)), 0..4),
        prop::collection::vec(joint, 0..3),
    )
        .prop_map(|(name, bodies, joints)| Robot {
            name,
            bodies: bodies
                .into_iter()
                .map(|(placement, motors)| RobotBody { placement, motors })
                .collect(),
            joints,
            ..Robot::default()
        });
    let scene_robot = (name(), number(), number(), number(), velocity()).prop_map(
        |(source, x, y, orientation, velocity)| SceneRobot {
            source,
            x,
            y,
            orientation,
            velocity,
            ..SceneRobot::default()
        },
    );
    let scene = (
        name(),
        number(),
        number(),
        prop::option::of(number()),
        prop::option::of(name()),
        prop::collection::vec(scene_robot, 0..3),
        prop::collection::vec(placement(), 0..3),
    )
        .prop_map(
            |(name, gravitation, friction, timestep, solver, robots, bodies)| Scene {
                name,
                gravitation,
                friction,
                timestep,
                solver,
                robots,
                bodies,
                ..Scene::default()
            },
        );
    (
        prop::collection::vec(body, 0..4),
        prop::collection::vec(robot, 0..3),
        prop::collection::vec(scene, 0..3),
    )
        .prop_map(|(bodies, robots, scenes)| Model {
            bodies,
            robots,
            scenes,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Save → load gives the same database, every f64 bit for bit. (Validity is not
    /// required to round-trip: a half-made robot in the editor saves and loads too.)
    #[test]
    fn save_then_load_is_the_identity(model in model()) {
        let dir = tempfile::tempdir().unwrap();
        let mut db = Database::new(model.clone());
        db.save_to(dir.path(), Overwrite::Never).unwrap();
        let (loaded, problems) = Database::load(dir.path());
        prop_assert!(problems.iter().all(|p| !p.message.contains("not a number") && !p.message.contains("malformed")), "{problems:#?}");
        prop_assert_eq!(&loaded.model, &model);
        for (a, b) in loaded.model.bodies.iter().zip(&model.bodies) {
            prop_assert_eq!(a.density.to_bits(), b.density.to_bits());
        }
    }
}

/// Tabs and line breaks inside names and other texts survive save and load (found by the
/// `xml_database` fuzz target: a name written `a&#10;b` was saved with a literal newline,
/// which XML reads back as a space).
#[test]
fn line_breaks_and_tabs_in_texts_round_trip() {
    let texts = ["a\nb", "tab\there", "cr\r\nlf", "&#10; <\"quoted\">"];
    let mut model = Model::default();
    for (i, text) in texts.iter().enumerate() {
        model.bodies.push(BodyDef {
            name: text.to_string(),
            density: 1.0,
            extra: vec![("note".into(), format!("{text} {i}"))],
            ..BodyDef::default()
        });
        model.scenes.push(Scene {
            name: format!("{text}{i}"),
            solver: Some(text.to_string()),
            ..Scene::default()
        });
    }
    let dir = tempfile::tempdir().unwrap();
    Database::new(model.clone())
        .save_to(dir.path(), Overwrite::Never)
        .unwrap();
    let (loaded, _) = Database::load(dir.path());
    assert_eq!(loaded.model, model);
}

/// One broken file: what it is, and what its error must say.
struct Broken {
    file: &'static str,
    kind: FileKind,
    severity: Severity,
    says: &'static str,
    line: Option<usize>,
}

#[test]
fn each_broken_bodies_file_gives_its_specific_problem() {
    use FileKind::*;
    use Severity::*;
    each_gives_its_problem(&[
        Broken {
            file: "truncated_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "malformed XML",
            line: Some(5),
        },
        Broken {
            file: "wrong_type_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "density=\"lots\" is not a number",
            line: Some(2),
        },
        Broken {
            file: "nan_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "density=\"NaN\" is not a finite number",
            line: Some(2),
        },
        Broken {
            file: "inf_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "x=\"inf\" is not a finite number",
            line: Some(4),
        },
        Broken {
            file: "missing_attribute_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "missing attribute cor",
            line: Some(2),
        },
        Broken {
            file: "repeated_attribute_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "duplicated attribute",
            line: Some(2),
        },
        Broken {
            file: "nonconvex_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "not convex",
            line: Some(2),
        },
        Broken {
            file: "duplicate_names_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "already used on line 2",
            line: Some(7),
        },
        Broken {
            file: "bad_ranges_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "density -1 is negative",
            line: Some(2),
        },
        Broken {
            file: "bad_ranges_bodies.xml",
            kind: Bodies,
            severity: Error,
            says: "cor 1.5 is outside [0, 1]",
            line: Some(2),
        },
    ]);
}

#[test]
fn each_broken_robots_file_gives_its_specific_problem() {
    use FileKind::*;
    use Severity::*;
    each_gives_its_problem(&[
        Broken {
            file: "dangling_robots.xml",
            kind: Robots,
            severity: Error,
            says: "source \"no such body\" is not a body",
            line: Some(3),
        },
        Broken {
            file: "dangling_robots.xml",
            kind: Robots,
            severity: Error,
            says: "bodyB \"c\" is not a body of this robot",
            line: Some(5),
        },
        Broken {
            file: "disconnected_robots.xml",
            kind: Robots,
            severity: Error,
            says: "not all bodies are connected",
            line: Some(2),
        },
        Broken {
            file: "anchor_outside_robots.xml",
            kind: Robots,
            severity: Warning,
            says: "lies in neither body",
            line: Some(5),
        },
    ]);
}

#[test]
fn each_broken_scenes_file_gives_its_specific_problem() {
    use FileKind::*;
    use Severity::*;
    each_gives_its_problem(&[
        Broken {
            file: "dangling_scenes.xml",
            kind: Scenes,
            severity: Error,
            says: "source \"no such robot\" is not a robot",
            line: Some(3),
        },
        Broken {
            file: "dangling_scenes.xml",
            kind: Scenes,
            severity: Error,
            says: "source \"no such body\" is not a body",
            line: Some(4),
        },
        Broken {
            file: "mismatched_scenes.xml",
            kind: Scenes,
            severity: Error,
            says: "malformed XML",
            line: Some(4),
        },
        Broken {
            file: "empty_scenes.xml",
            kind: Scenes,
            severity: Error,
            says: "no root element",
            line: None,
        },
    ]);
}

/// Loads each case's file (beside a valid bodies.xml) and finds its problem, with its
/// severity and line, in a message that names the file.
fn each_gives_its_problem(cases: &[Broken]) {
    for case in cases {
        let text = std::fs::read(Path::new("tests/corpus").join(case.file)).unwrap();
        let mut files: Vec<(FileKind, &[u8])> = vec![(case.kind, &text)];
        if case.kind != FileKind::Bodies {
            files.push((FileKind::Bodies, BOX_BODIES.as_bytes()));
        }
        let (_, problems, dir) = load(&files);
        let path = dir.path().join(case.kind.file_name()).display().to_string();
        let found = problems
            .iter()
            .find(|p| p.message.contains(case.says) && p.file == path);
        let Some(found) = found else {
            panic!(
                "{}: no problem saying {:?} in {problems:#?}",
                case.file, case.says
            )
        };
        assert_eq!(found.severity, case.severity, "{}: {found}", case.file);
        assert_eq!(
            found.location.map(|l| l.line),
            case.line,
            "{}: {found}",
            case.file
        );
        assert!(
            found.to_string().starts_with(&path),
            "names the file: {found}"
        );
    }
}

#[test]
fn one_broken_file_does_not_stop_the_others() {
    let robots = std::fs::read("data/robots.xml").unwrap();
    let (db, problems, _dir) = load(&[
        (FileKind::Bodies, b"<bodies><body name="),
        (FileKind::Robots, &robots),
    ]);
    assert!(
        problems
            .iter()
            .any(|p| p.file.ends_with("bodies.xml") && p.message.contains("malformed"))
    );
    let written = String::from_utf8_lossy(&robots).matches("<robot ").count();
    assert_eq!(db.model.robots.len(), written, "robots.xml still loads");
    // …and its references to the lost bodies are reported, not silently dropped.
    assert!(
        problems
            .iter()
            .any(|p| p.file.ends_with("robots.xml") && p.message.contains("is not a body"))
    );
}

#[test]
fn generated_monsters_give_errors_not_panics() {
    // A 10 MB attribute.
    let huge = format!(
        "<bodies><body name=\"{}\" density=\"x{}\" cor=\"0\"/></bodies>",
        "n".repeat(10),
        "9".repeat(10 << 20)
    );
    let (_, problems, _dir) = load(&[(FileKind::Bodies, huge.as_bytes())]);
    let p = problems
        .iter()
        .find(|p| p.message.contains("is not a number"))
        .expect("a number error");
    assert!(
        p.message.len() < 200,
        "the message clips the value: {} characters",
        p.message.len()
    );
    // A million unknown elements (4 MiB) in one body, and a million stray texts: a
    // million warnings took 130 times the file in memory. The first hundred of each are
    // listed, the rest counted.
    let many = format!(
        "<bodies><body name=\"b\" density=\"1\" cor=\"0\">{}</body><body name=\"t\" density=\"1\" cor=\"0\">{}</body></bodies>",
        "<x/>".repeat(1 << 20),
        "<vertex x=\"0\" y=\"0\">t</vertex>".repeat(1 << 18),
    );
    let (_, problems, _dir) = load(&[(FileKind::Bodies, many.as_bytes())]);
    let warnings = problems.iter().filter(|p| !p.is_error()).count();
    assert!(warnings <= 2 * 101, "{warnings} warnings listed");
    let counted: Vec<&str> = problems
        .iter()
        .filter(|p| p.message.contains("more warnings not listed"))
        .map(|p| p.message.as_str())
        .collect();
    assert_eq!(
        counted,
        [
            "262044 more warnings not listed (the first 100 are)",
            "1048476 more warnings not listed (the first 100 are)"
        ]
    );
    // Errors are capped as warnings are: 300 vertices without coordinates.
    let vertices = format!(
        "<bodies><body name=\"v\" density=\"1\" cor=\"0\">{}</body></bodies>",
        "<vertex/>".repeat(300)
    );
    let (_, problems, _dir) = load(&[(FileKind::Bodies, vertices.as_bytes())]);
    let errors: Vec<&str> = problems
        .iter()
        .filter(|p| p.is_error())
        .map(|p| p.message.as_str())
        .collect();
    assert_eq!(errors.len(), 101, "{errors:?}");
    assert!(errors.contains(&"500 more errors not listed (the first 100 are)"));
    // More elements than any database has: refused as they are counted, before the
    // tree takes 88 bytes for each 4-byte element.
    let elements = format!("<bodies>{}</bodies>", "<x/>".repeat((1 << 22) + 1));
    let (_, problems, _dir) = load(&[(FileKind::Bodies, elements.as_bytes())]);
    assert!(
        problems
            .iter()
            .any(|p| p.is_error() && p.message.contains("more than 4194304 elements")),
        "{:?}",
        &problems[..problems.len().min(3)]
    );
    // Control characters in stray text and in attribute names are escaped once.
    let controls = "<bodies>stray\u{0}text<body name=\"b\" density=\"1\" cor=\"0\"><vertex x=\"0\" y=\"0\" q\u{1}=\"2\"/><vertex x=\"1\" y=\"0\"/><vertex x=\"0\" y=\"1\"/></body></bodies>";
    let (_, problems, _dir) = load(&[(FileKind::Bodies, controls.as_bytes())]);
    let messages: Vec<&str> = problems.iter().map(|p| p.message.as_str()).collect();
    assert_eq!(
        messages,
        [
            "unexpected text \"stray\\u{0}text\", ignored (and not kept when this file is saved)",
            "unknown attributes \"q\\u{1}\" are not kept"
        ]
    );
    // Deep nesting.
    let deep = format!("{}{}", "<a>".repeat(100_000), "</a>".repeat(100_000));
    let (_, problems, _dir) = load(&[(FileKind::Robots, deep.as_bytes())]);
    assert!(
        problems
            .iter()
            .any(|p| p.message.contains("nested deeper than")),
        "{problems:#?}"
    );
    // Invalid UTF-8 on line 3.
    let bad = b"<scenes>\n  <scene name=\"caf\xe9\" gravitation=\"1\" friction=\"0\"/>\n</scenes>"
        .to_vec();
    let (_, problems, _dir) = load(&[(FileKind::Scenes, &bad)]);
    let p = problems
        .iter()
        .find(|p| p.message.contains("not valid UTF-8"))
        .expect("a UTF-8 error");
    assert_eq!(p.location.map(|l| l.line), Some(2));
}

/// Every problem prints as one line (the CLI's promise), even when the name or the tag it
/// quotes has a newline in it (found by the `xml_database` fuzz target: `</\n>`).
#[test]
fn problems_are_one_line_whatever_they_quote() {
    let (_, problems, _dir) = load(&[
        (FileKind::Bodies, b"</\n>"),
        (
            FileKind::Scenes,
            b"<scenes><scene name=\"two&#10;lines&#13;\" gravitation=\"1\" friction=\"-1\"/></scenes>",
        ),
    ]);
    assert_eq!(problems.len(), 2, "{problems:#?}");
    for p in &problems {
        let line = p.to_string();
        assert!(!line.contains(['\n', '\r']), "{line:?}");
    }
    assert!(problems[0].message.contains("`</\\n>`"), "{}", problems[0]);
    assert!(
        problems[1].element.contains("two\\nlines\\r"),
        "{}",
        problems[1]
    );
}

#[test]
fn missing_files_are_empty_collections() {
    let (db, problems, _dir) = load(&[]);
    assert!(problems.is_empty());
    assert_eq!(db.model, Model::default());
}

#[test]
fn a_save_interrupted_before_the_rename_leaves_the_old_files_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    for kind in FileKind::ALL {
        std::fs::copy(
            Path::new("data").join(kind.file_name()),
            dir.path().join(kind.file_name()),
        )
        .unwrap();
    }
    let before: Vec<Vec<u8>> = FileKind::ALL
        .iter()
        .map(|k| std::fs::read(dir.path().join(k.file_name())).unwrap())
        .collect();
    let (mut db, _) = Database::load(dir.path());
    db.model.bodies[0].density = 2.0;
    db.model.scenes.clear();
    let crash = db.save_with(dir.path(), Overwrite::Never, |_| {
        Err(std::io::Error::other("power cut"))
    });
    assert!(matches!(crash, Err(SaveError::Io { .. })));
    let after: Vec<Vec<u8>> = FileKind::ALL
        .iter()
        .map(|k| std::fs::read(dir.path().join(k.file_name())).unwrap())
        .collect();
    assert_eq!(before, after);
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        leftovers.len(),
        3,
        "no temporary file is left behind: {leftovers:?}"
    );
    // And a save that completes writes what was asked.
    db.save(Overwrite::Never).unwrap();
    let (again, _) = Database::load(dir.path());
    assert_eq!(again.model, db.model);
}

#[test]
fn a_file_changed_on_disk_is_not_overwritten_without_confirmation() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), FileKind::Bodies, BOX_BODIES);
    let (mut db, _) = Database::load(dir.path());
    db.model.bodies[0].cor = 0.5;
    let theirs = BOX_BODIES.replace("cor=\"0.2\"", "cor=\"0.9\"");
    write(dir.path(), FileKind::Bodies, &theirs);
    assert_eq!(db.changed_on_disk(), vec![FileKind::Bodies]);
    assert!(matches!(
        db.save(Overwrite::Never),
        Err(SaveError::ChangedOnDisk(_))
    ));
    assert_eq!(
        std::fs::read_to_string(dir.path().join("bodies.xml")).unwrap(),
        theirs
    );
    db.save(Overwrite::Confirmed).unwrap();
    assert_eq!(Database::load(dir.path()).0.model.bodies[0].cor, 0.5);
}

#[test]
fn a_file_with_skipped_records_is_not_saved_over_without_confirmation() {
    let text = std::fs::read("tests/corpus/wrong_type_bodies.xml").unwrap();
    let (mut db, _, dir) = load(&[(FileKind::Bodies, &text)]);
    assert_eq!(db.model.bodies.len(), 1, "the readable record loads");
    db.model.bodies[0].cor = 0.3;
    assert!(matches!(
        db.save(Overwrite::Never),
        Err(SaveError::WouldDropRecords(_))
    ));
    assert_eq!(std::fs::read(dir.path().join("bodies.xml")).unwrap(), text);
}

#[test]
fn renames_follow_references_and_deletes_check_them() {
    let mut m = Database::embedded().0.model;
    m.rename_body("obdelnik", "rectangle").unwrap();
    assert!(
        m.robot("housenka")
            .unwrap()
            .bodies
            .iter()
            .all(|b| b.placement.source == "rectangle")
    );
    assert_eq!(
        m.scene("testovaci scena").unwrap().bodies[0].source,
        "rectangle"
    );
    m.rename_robot("housenka", "caterpillar").unwrap();
    assert_eq!(
        m.scene("testovaci scena").unwrap().robots[0].source,
        "caterpillar",
        "the untrimmed reference too"
    );
    assert_eq!(
        m.rename_body("rectangle", "floor"),
        Err(EditError::Taken("floor".into()))
    );
    let refused = m.delete_body("rectangle", Delete::IfUnused).unwrap_err();
    let EditError::InUse { users, .. } = refused else {
        panic!()
    };
    assert!(
        users.contains(&User::Robot("caterpillar".into()))
            && users.contains(&User::Scene("testovaci scena".into()))
    );
    m.delete_body("rectangle", Delete::Cascade).unwrap();
    assert!(
        m.robot("caterpillar").unwrap().bodies.is_empty()
            && m.robot("caterpillar").unwrap().joints.is_empty()
    );
    assert!(m.scene("testovaci scena").unwrap().bodies.is_empty());
    assert!(matches!(
        m.delete_robot("car", Delete::IfUnused),
        Err(EditError::InUse { .. })
    ));
    m.delete_robot("car", Delete::Cascade).unwrap();
    assert!(
        robosim::db::check(&m, |k| k.file_name().to_string())
            .iter()
            .all(|p| !p.message.contains("\"car\""))
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Loading never panics: the default files with a random slice cut out, random bytes
    /// spliced in, or both; whatever is left loads, with problems where it must.
    #[test]
    fn any_mangled_file_loads_without_panicking(
        which in 0usize..3,
        cut in (0.0f64..1.0, 0usize..200),
        splice in prop::collection::vec(any::<u8>(), 0..40),
    ) {
        let kind = FileKind::ALL[which];
        let mut bytes = std::fs::read(Path::new("data").join(kind.file_name())).unwrap();
        let start = (cut.0 * bytes.len() as f64) as usize;
        let end = (start + cut.1).min(bytes.len());
        bytes.splice(start..end, splice);
        let (db, problems, _dir) = load(&[(kind, &bytes)]);
        // Every problem names the file it is about.
        prop_assert!(problems.iter().all(|p| p.file.ends_with(".xml")));
        let _ = db.check();
    }
}

#[test]
fn a_database_is_dirty_only_between_an_edit_and_its_save() {
    // The default files are hand-formatted, so their text differs from what a save writes:
    // dirtiness must compare models, not text, or a fresh load would already ask to save.
    let dir = tempfile::tempdir().unwrap();
    for kind in FileKind::ALL {
        let from = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data")
            .join(kind.file_name());
        std::fs::copy(from, dir.path().join(kind.file_name())).unwrap();
    }
    let (mut db, _) = Database::load(dir.path());
    assert!(!db.is_dirty());
    let density = db.model.bodies[0].density;
    db.model.bodies[0].density = density + 1.0;
    assert!(db.is_dirty());
    db.model.bodies[0].density = density;
    assert!(!db.is_dirty(), "an edit undone leaves nothing to save");
    db.model.bodies[0].density = density + 1.0;
    db.save(Overwrite::Never).unwrap();
    assert!(!db.is_dirty());
    assert_eq!(Database::load(dir.path()).0.model, db.model);
}

#[test]
fn names_with_surrounding_spaces_can_be_referred_to() {
    // Found by the fuzzing helper: references were trimmed, stored names were not, so a
    // body, robot or scene named " x " could never be found, while check (which compares
    // names trimmed) raised nothing.
    let (db, _) = Database::embedded();
    let mut model = db.model;
    let body = model.bodies[0].name.clone();
    let robot = model.robots[0].name.clone();
    let scene = model.scenes[0].name.clone();
    model.bodies[0].name = format!(" {body}\t");
    model.robots[0].name = format!("  {robot} ");
    model.scenes[0].name = format!("{scene} ");
    assert!(model.body(&body).is_some());
    assert!(model.robot(&format!(" {robot}")).is_some());
    assert!(model.scene(&scene).is_some());
    let alias = model.robots[0].bodies[0].placement.alias.clone();
    model.robots[0].bodies[0].placement.alias = format!(" {alias} ");
    assert!(model.robots[0].body(&alias).is_some());
}

#[test]
fn rename_and_delete_follow_names_with_surrounding_spaces() {
    // Lookups ignored the spaces around a stored name while rename and delete compared
    // references with the stored name as written: renaming " x " left its references
    // dangling, and a cascade delete left its placements behind.
    let (db, _) = Database::embedded();
    let mut model = db.model;
    let body = model.robots[0].bodies[0]
        .placement
        .source
        .trim()
        .to_string();
    let index = model.bodies.iter().position(|b| b.name == body).unwrap();
    let stored = format!(" {body} ");
    model.bodies[index].name = stored.clone();
    // The robot's joints name their bodies with spaces around the aliases, too.
    for j in &mut model.robots[0].joints {
        j.body_a = format!(" {} ", j.body_a);
        j.body_b = format!(" {} ", j.body_b);
    }
    assert!(!model.robots[0].joints.is_empty());
    let uses = |m: &Model, name: &str| {
        m.robots
            .iter()
            .flat_map(|r| &r.bodies)
            .filter(|b| same_name(&b.placement.source, name))
            .count()
            + m.scenes
                .iter()
                .flat_map(|s| &s.bodies)
                .filter(|b| same_name(&b.source, name))
                .count()
    };
    let before = uses(&model, &body);
    assert!(before > 0);
    model.rename_body(&stored, "renamed").unwrap();
    assert_eq!(uses(&model, "renamed"), before);
    assert_eq!(uses(&model, &body), 0);
    model.bodies[index].name = " renamed ".into();
    model.delete_body(" renamed ", Delete::Cascade).unwrap();
    assert_eq!(uses(&model, "renamed"), 0);
    // No joint is left pinning a body the cascade removed.
    for r in &model.robots {
        for j in &r.joints {
            let placed = |alias: &str| r.body(alias).is_some();
            assert!(placed(&j.body_a) && placed(&j.body_b), "{}: {j:?}", r.name);
        }
    }
}
