//! How a config becomes a sample: a sample file whose radius is the material's loads and one
//! whose radius is not is refused by name; a cut top with an automatic footprint widens until
//! the monomers fit below the side; a cylinder takes the radius the config sets.

mod common;

use common::printed::RADIUS;
use common::Scratch;
use dustdem::config::Config;
use dustdem::experiment::setup::{build_sample, build_walls};
use dustdem::sample::Footprint;

fn config(text: &str) -> Config {
    Config::parse(text, "setup").unwrap()
}

#[test]
fn a_sample_file_loads_with_the_material_radius_and_is_refused_with_another() {
    let dir = Scratch::new("setup-file");
    let rbd = config("[sample]\nmonomers = 50\nseed = 4\n");
    let sample = build_sample(&rbd, &rbd.contact_law()).unwrap();
    let path = dir.join("sample.txt");
    sample.save(&path).unwrap();
    let from_file = |radius_um: f64| {
        let c = config(&format!(
            "[sample]\nsource = \"file\"\nfile = \"{}\"\nmonomers = 50\n\
             [material]\nradius_um = {radius_um}\n",
            path.display()
        ));
        build_sample(&c, &c.contact_law())
    };
    let loaded = from_file(RADIUS * 1e4).unwrap();
    assert_eq!(loaded.positions, sample.positions);
    let e = from_file(0.61).unwrap_err().to_string();
    assert!(
        e.contains("radius_um = 0.61") && e.contains("differs"),
        "{e}"
    );
}

#[test]
fn a_cut_top_with_an_automatic_footprint_widens_until_the_sample_fits_below_its_side() {
    let c = config("[sample]\nmonomers = 50\nseed = 2\ntop = \"cut\"\n");
    let sample = build_sample(&c, &c.contact_law()).unwrap();
    let Footprint::Box { side } = sample.footprint else {
        panic!("{:?}", sample.footprint)
    };
    assert_eq!(sample.positions.len(), 50);
    // Every monomer wholly below a height equal to the side.
    assert!(
        sample.z_max() + RADIUS <= side,
        "{} > {side}",
        sample.z_max()
    );
    // The cube of φ = 0.15 holding 50 monomers has a side of (50 v / 0.15)^⅓ = 6.706 µm
    // (v = 4/3 π (0.6 µm)³ = 0.904 779 µm³); so few monomers do not fit below it (their wall
    // layers are sparse), and the side widens by 1% steps (measured: two, 6.841 µm).
    assert!(
        side > 1.005 * 6.706e-4 && side < 1.49 * 6.706e-4,
        "side {side}"
    );
}

#[test]
fn a_cylinder_takes_the_radius_the_config_sets() {
    let c = config(
        "[sample]\nmonomers = 100\nfootprint = \"cylinder\"\ncylinder_radius_um = 9.5\n\
         [experiment]\nkind = \"uni\"\n",
    );
    let sample = build_sample(&c, &c.contact_law()).unwrap();
    assert_eq!(sample.footprint, Footprint::Cylinder { radius: 9.5e-4 });
}

#[test]
fn an_automatic_cylinder_has_the_automatic_box_base_and_a_cut_top_at_its_square_side() {
    let c = config(
        "[sample]\nmonomers = 400\nseed = 5\nfootprint = \"cylinder\"\ntop = \"cut\"\n\
         [experiment]\nkind = \"uni\"\n",
    );
    let sample = build_sample(&c, &c.contact_law()).unwrap();
    let Footprint::Cylinder { radius } = sample.footprint else {
        panic!("{:?}", sample.footprint)
    };
    // The cube of φ = 0.15 holding 400 monomers: side (400 v / 0.15)^⅓ = 13.413 µm, so a base
    // of the same area has the radius 13.413 / √π = 7.5675 µm, widened by 1% steps until the
    // monomers fit (measured: one step).
    let steps = (radius / 7.5675e-4).ln() / 1.01f64.ln();
    assert!(
        (steps - steps.round()).abs() < 0.01 && (0.0..=40.0).contains(&steps),
        "radius {radius}: {steps} steps"
    );
    // Cut at the side of the square with that base, r √π.
    let (top, height) = (
        sample.z_max() + RADIUS,
        radius * std::f64::consts::PI.sqrt(),
    );
    assert!(
        top <= height && top > 0.9 * height,
        "top {top}, cut at {height}"
    );
}

#[test]
fn the_omni_box_walls_stand_at_half_the_side_facing_in() {
    let c = config("[sample]\nmonomers = 100\nside_um = 9\n");
    let law = c.contact_law();
    let sample = build_sample(&c, &law).unwrap();
    let walls = build_walls(&c, &law, &sample).unwrap();
    let half = 4.5e-4;
    let expected = [
        ("side x-", [-half, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ("side x+", [half, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ("side y-", [0.0, -half, 0.0], [0.0, 1.0, 0.0]),
        ("side y+", [0.0, half, 0.0], [0.0, -1.0, 0.0]),
    ];
    assert_eq!(walls.len(), 6);
    for (wall, (name, point, normal)) in walls[2..].iter().zip(expected) {
        assert_eq!(wall.name, name);
        // 0.5 × 9e-4 cm carries one rounding.
        let off = (wall.point - glam::DVec3::from_array(point)).length();
        assert!(off < 1e-18, "{name}: {} against {point:?}", wall.point);
        assert_eq!(wall.normal.to_array(), normal, "{name}");
    }
}
