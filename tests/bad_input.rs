//! Values ODE would abort on are refused with an error naming them.

use psa_esp::ode::{Mass, World};
use psa_esp::physics::{create_backend, BackendKind, BodyState, StepSettings};
use psa_esp::psa::BodySettings;

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
