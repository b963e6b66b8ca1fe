//! Values ODE would abort on are refused with an error naming them.

use psa_sim::ode::{Mass, World};
use psa_sim::physics::{create_backend, BackendKind, BodyState, StepSettings};
use psa_sim::psa::BodySettings;

fn err_text<T>(result: Result<T, impl std::fmt::Display>) -> String {
    match result {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn non_positive_density_or_mass_is_an_error_naming_the_value() {
    for density in [0.0, -1000.0, f64::NAN] {
        let body = BodySettings {
            density,
            ..BodySettings::default()
        };
        let msg = err_text(body.model());
        assert!(msg.contains("density") && msg.contains(&density.to_string()), "{msg}");
        let msg = err_text(Mass::cuboid(density, [1.0, 1.0, 1.0]));
        assert!(msg.contains("density"), "{msg}");
    }
    let msg = err_text(
        BodySettings {
            hull_radius: -0.1,
            ..BodySettings::default()
        }
        .model(),
    );
    assert!(msg.contains("-0.1"), "{msg}");
    let msg = err_text(
        BodySettings {
            max_force: 0.0,
            ..BodySettings::default()
        }
        .model(),
    );
    assert!(msg.contains("force"), "{msg}");
}

#[test]
fn a_mass_ode_would_abort_on_is_refused_before_ode_sees_it() {
    let world = World::new().unwrap();
    let body = world.create_body().unwrap();
    // Centre of mass away from the body origin: dBodySetMass would abort.
    let mut off_centre = Mass::cuboid(1000.0, [0.1, 0.1, 0.1]).unwrap();
    off_centre.translate([0.05, 0.0, 0.0]).unwrap();
    let msg = err_text(body.set_mass(&off_centre));
    assert!(msg.contains("centre of mass") && msg.contains("0.05"), "{msg}");
    let msg = err_text(off_centre.translate([f64::NAN, 0.0, 0.0]));
    assert!(msg.contains("NaN"), "{msg}");
    // A valid mass is accepted and stored as given.
    let good = Mass::cylinder_z(1000.0, 0.1, 0.1).unwrap();
    body.set_mass(&good).unwrap();
    assert_eq!(body.mass().total(), good.total());
}

#[test]
fn nan_or_out_of_range_thrust_is_an_error_on_every_backend() {
    let model = BodySettings::default().model().unwrap();
    for kind in BackendKind::available() {
        let mut b = create_backend(kind, &model, &StepSettings::default()).unwrap();
        for (thrust, shown) in [(f64::NAN, "NaN"), (1.5, "1.5"), (-0.2, "-0.2"), (f64::INFINITY, "inf")] {
            let msg = err_text(b.step(&[0.0, thrust, 0.0, 0.0]));
            assert!(msg.contains("thruster 1") && msg.contains(shown), "{kind}: {msg}");
        }
        let msg = err_text(b.step(&[0.0; 3]));
        assert!(msg.contains("expected 4"), "{kind}: {msg}");
        let msg = err_text(b.reset(&BodyState {
            vx: f64::NAN,
            ..BodyState::default()
        }));
        assert!(msg.contains("finite"), "{kind}: {msg}");
        // The backend is still usable after refusing.
        b.step(&[0.5; 4]).unwrap();
    }
}

#[test]
fn non_positive_time_step_is_an_error() {
    let model = BodySettings::default().model().unwrap();
    for dt in [0.0, -0.05, f64::NAN] {
        let settings = StepSettings {
            dt,
            ..StepSettings::default()
        };
        for kind in BackendKind::available() {
            let msg = err_text(create_backend(kind, &model, &settings));
            assert!(msg.contains("dt") && msg.contains(&dt.to_string()), "{kind}: {msg}");
        }
        let world = World::new().unwrap();
        let msg = err_text(world.step(dt));
        assert!(msg.contains("dt") && msg.contains(&format!("{dt:?}")), "{msg}");
        let msg = err_text(world.quick_step(dt));
        assert!(msg.contains("dt"), "{msg}");
    }
}

#[test]
fn a_step_ode_would_abort_on_is_refused_alike_by_every_backend() {
    // No range check in front: a model straight from the library with a
    // force of 1e98 N, spun up at full torque until the guard refuses.
    let mut model = BodySettings::default().model().unwrap();
    model.max_force = 1e98;
    let mut refused_at = Vec::new();
    for kind in BackendKind::available() {
        let mut b = create_backend(kind, &model, &StepSettings::default()).unwrap();
        let steps = (1..10_000).find(|_| b.step(&[1.0, 1.0, 0.0, 0.0]).is_err());
        let steps = steps.unwrap_or_else(|| panic!("{kind}: never refused"));
        let msg = err_text(b.step(&[1.0, 1.0, 0.0, 0.0]));
        assert!(msg.contains("beyond what the engines integrate"), "{kind}: {msg}");
        let s = b.state();
        assert!(
            s.omega.is_finite() && s.vx.is_finite() && s.x.is_finite(),
            "{kind}: {s:?}"
        );
        refused_at.push(steps);
        // A start that far out is refused by reset already.
        let msg = err_text(b.reset(&BodyState {
            omega: 1e160,
            ..BodyState::default()
        }));
        assert!(msg.contains("1e160"), "{kind}: {msg}");
    }
    assert!(
        refused_at.iter().all(|&n| n == refused_at[0] && n > 10),
        "{refused_at:?}"
    );
}

#[test]
fn a_time_step_too_long_to_integrate_is_refused_when_the_backend_is_built() {
    let model = BodySettings::default().model().unwrap();
    let settings = StepSettings {
        dt: 1e300,
        ..StepSettings::default()
    };
    for kind in BackendKind::available() {
        let msg = err_text(create_backend(kind, &model, &settings));
        assert!(msg.contains("dt = 1e300"), "{kind}: {msg}");
    }
}

#[test]
fn the_most_violent_body_the_ranges_allow_never_reaches_the_guard() {
    // Every range at the end that spins and pushes hardest: the lightest,
    // smallest body, the longest arms, the strongest thrusters, the longest
    // step and trial, full torque all the way (native: the cheapest engine,
    // with the same guard as the others).
    let body = BodySettings {
        hull_radius: 0.01,
        hull_height: 0.01,
        thruster_size: [0.001; 3],
        mount_radius: 2.0,
        density: 1.0,
        max_force: 100.0,
    };
    let settings = StepSettings {
        dt: 1.0,
        ..StepSettings::default()
    };
    let model = body.model().unwrap();
    let mut b = create_backend(BackendKind::Native, &model, &settings).unwrap();
    b.reset(&BodyState {
        x: 100.0,
        y: 100.0,
        vx: 10.0,
        vy: 10.0,
        omega: 100.0,
        heading: 0.0,
    })
    .unwrap();
    for _ in 0..psa_sim::psa::settings::limits::MAX_STEPS {
        b.step(&[1.0, 1.0, 0.0, 0.0]).unwrap();
    }
    assert!(b.state().omega > 1e14, "it did spin up: {:?}", b.state());
}

#[test]
fn every_range_of_the_limits_table_is_enforced_from_a_configuration() {
    use psa_experiment::RunConfig;
    use psa_sim::psa::settings::limits::LIMITS;
    let defaults = toml::Table::try_from(RunConfig::default()).unwrap();
    let problem = defaults["problem"].as_table().unwrap();
    let mut checked = 0;
    for limit in LIMITS.iter().filter(|l| !l.key.starts_with("start.")) {
        let (table, name) = limit.key.rsplit_once('.').unwrap_or(("", limit.key));
        let current = if table.is_empty() {
            &problem[name]
        } else {
            &problem[table].as_table().unwrap()[name]
        };
        // Just above the range, in the type the key has.
        let above = |v: &toml::Value| match v {
            toml::Value::Integer(_) => toml::Value::Integer(limit.max as i64 + 1),
            _ => toml::Value::Float(limit.max * 1.5 + 1.0),
        };
        let value = match current {
            toml::Value::Array(items) => toml::Value::Array(items.iter().map(above).collect()),
            v => above(v),
        };
        let section = if table.is_empty() {
            "[problem]".to_string()
        } else {
            format!("[problem.{table}]")
        };
        let text = format!("{section}\n{name} = {value}\n");
        let err = format!("{:#}", RunConfig::default().with_overrides(&text).unwrap_err());
        assert!(err.contains(limit.key) && err.contains("is outside"), "{text}: {err}");
        checked += 1;
    }
    assert!(checked >= 25, "{checked}");
}
