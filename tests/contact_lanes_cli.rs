//! The lane choice from the command line: a run writes the same curve whichever lanes
//! evaluate the contacts, and an unknown choice is refused before anything is written.

use dustdem::backend::cpu::lanes::ContactLanes;

mod common;

fn run_with_lanes(dir: &std::path::Path, lanes: Option<&str>) -> std::process::Output {
    let config = dir.join("run.toml");
    std::fs::write(
        &config,
        "[sample]\nmonomers = 300\nseed = 5\n[experiment]\nkind = \"omni\"\nwall_speed_m_s = 5.0\nphi_stop = 0.3\n",
    )
    .unwrap();
    let out = dir.join(format!("out-{}", lanes.unwrap_or("default")));
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_dustdem"));
    command.args([
        "run",
        config.to_str().unwrap(),
        "--backend",
        "cpu",
        "--quiet",
        "--out",
    ]);
    command.arg(&out);
    if let Some(lanes) = lanes {
        command.env(dustdem::backend::cpu::lanes::CONTACT_LANES_VAR, lanes);
    }
    command.output().unwrap()
}

#[test]
fn a_run_writes_the_same_curve_whichever_lanes_evaluate_the_contacts() {
    let dir = common::Scratch::new("contact-lanes-run");
    let mut curves = vec![];
    let mut choices = vec![Some("scalar"), Some("portable"), None];
    if ContactLanes::detected() == ContactLanes::Avx2 {
        // Named explicitly, it must be accepted where the processor has it.
        choices.push(Some("avx2"));
    }
    for lanes in choices {
        let run = run_with_lanes(dir.path(), lanes);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let out = dir.join(format!("out-{}", lanes.unwrap_or("default")));
        curves.push(std::fs::read(out.join("curve.csv")).unwrap());
    }
    assert!(curves[0].len() > 1000, "a curve of some rows");
    assert!(curves.iter().all(|c| *c == curves[0]));
}

#[test]
fn an_unknown_lane_choice_is_refused_naming_the_variable_value_and_choices() {
    let dir = common::Scratch::new("contact-lanes-bad");
    let run = run_with_lanes(dir.path(), Some("wide"));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    for needle in [
        "DUSTDEM_CONTACT_LANES",
        "\"wide\"",
        "scalar, portable and avx2",
    ] {
        assert!(stderr.contains(needle), "{needle}: {stderr}");
    }
    assert!(!dir.join("out-wide").exists(), "nothing written");
}
