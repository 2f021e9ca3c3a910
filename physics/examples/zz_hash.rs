// Scratch: bit-for-bit state fingerprint of a few soft scenes (not committed).
use pe::{BodyDef, ContactSolver, ConvexPolygon, JointDef, Vec2, World};

fn fingerprint(w: &World) -> u64 {
    let mut h: u64 = 1469598103934665603;
    for (_, b) in w.bodies() {
        for x in [
            b.position.x,
            b.position.y,
            b.angle,
            b.velocity.x,
            b.velocity.y,
            b.angular_velocity,
        ] {
            h = (h ^ x.to_bits()).wrapping_mul(1099511628211);
        }
    }
    h
}

fn main() {
    // pyramid
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = if std::env::var_os("ZZ_EXACT").is_some() {
        ContactSolver::Exact
    } else {
        ContactSolver::Soft
    };
    w.friction = 0.6;
    w.add_body(
        BodyDef::new(ConvexPolygon::rectangle(100.0, 1.0).unwrap(), 0.0)
            .at(Vec2::new(0.0, 0.5), 0.0),
    )
    .unwrap();
    let unit = ConvexPolygon::rectangle(1.0, 1.0).unwrap();
    for row in 0..12 {
        for i in 0..12 - row {
            let x = i as f64 - 0.5 * (11 - row) as f64 + 0.01 * row as f64;
            w.add_body(
                BodyDef::new(unit.clone(), 1.0)
                    .restitution(if i % 3 == 0 { 0.5 } else { 0.0 })
                    .at(Vec2::new(x, -0.5 - row as f64 - 0.3), 0.1 * (i % 2) as f64),
            )
            .unwrap();
        }
    }
    for _ in 0..300 {
        w.step(1.0 / 60.0);
    }
    println!("pyramid {:016x}", fingerprint(&w));
    // chain with heavy end + contacts with a mass ratio
    let mut w = World::new(Vec2::new(0.0, 10.0));
    w.settings.contact_solver = if std::env::var_os("ZZ_EXACT").is_some() {
        ContactSolver::Exact
    } else {
        ContactSolver::Soft
    };
    w.friction = 0.5;
    let link = ConvexPolygon::rectangle(1.0, 0.2).unwrap();
    let mut prev = None;
    for i in 0..10 {
        let d = if i == 9 { 500.0 } else { 1.0 };
        let b = w
            .add_body(BodyDef::new(link.clone(), d).at(Vec2::new(i as f64 + 0.5, 0.0), 0.0))
            .unwrap();
        w.add_joint(JointDef::new(b, prev, Vec2::new(i as f64, 0.0)))
            .unwrap();
        prev = Some(b);
    }
    w.add_body(
        BodyDef::new(ConvexPolygon::rectangle(40.0, 1.0).unwrap(), 0.0)
            .at(Vec2::new(0.0, 8.0), 0.0),
    )
    .unwrap();
    let light = w
        .add_body(
            BodyDef::new(ConvexPolygon::rectangle(1.0, 1.0).unwrap(), 1.0)
                .at(Vec2::new(-5.0, 7.0), 0.0),
        )
        .unwrap();
    let _ = light;
    w.add_body(
        BodyDef::new(ConvexPolygon::rectangle(1.0, 1.0).unwrap(), 1000.0)
            .at(Vec2::new(-5.0, 6.0), 0.0),
    )
    .unwrap();
    for _ in 0..300 {
        w.step(1.0 / 60.0);
    }
    println!("chain {:016x}", fingerprint(&w));
}
