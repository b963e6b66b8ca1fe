//! Physics against closed-form motion and hand computation, on every backend.

use std::f64::consts::PI;

use psa_sim::physics::{create_backend, wrap_angle, BackendKind, BodyState, PhysicsBackend, StepSettings};
use psa_sim::psa::BodySettings;

fn backend(kind: BackendKind) -> Box<dyn PhysicsBackend> {
    let model = BodySettings::default().model().unwrap();
    create_backend(kind, &model, &StepSettings::default()).unwrap()
}

/// Mass and z inertia of the default body, computed by hand from the spec:
/// a cylinder r = h = 0.10 m and four 0.04 x 0.02 x 0.02 m boxes whose
/// centres are 0.12 m from the axis, all at 1000 kg/m^3.
fn hand_mass_and_izz() -> (f64, f64) {
    let rho = 1000.0;
    let m_hull = rho * PI * 0.10 * 0.10 * 0.10;
    let m_box = rho * 0.04 * 0.02 * 0.02;
    let izz_hull = 0.5 * m_hull * 0.10 * 0.10;
    // Each box: (length^2 + width^2) / 12 about its centre, plus m r^2.
    let izz_box = m_box * (0.04 * 0.04 + 0.02 * 0.02) / 12.0 + m_box * 0.12 * 0.12;
    (m_hull + 4.0 * m_box, izz_hull + 4.0 * izz_box)
}

#[test]
fn mass_centre_and_inertia_match_hand_computation() {
    let (mass, izz) = hand_mass_and_izz();
    assert!((mass - 3.2055926535897936).abs() < 1e-12, "hand mass {mass}");
    // Ixx: hull m (3 r^2 + h^2) / 12; boxes on the x axis (thrusters 1, 3,
    // long side along y) and on the y axis (thrusters 0, 2, long side along x).
    let rho = 1000.0;
    let m_hull = rho * PI * 0.001;
    let m_box = rho * 0.04 * 0.02 * 0.02;
    let ixx = m_hull * (3.0 * 0.01 + 0.01) / 12.0
        + 2.0 * m_box * (0.04 * 0.04 + 0.02 * 0.02) / 12.0 // boxes at (+-r, 0): sides y = 0.04, z = 0.02
        + 2.0 * (m_box * (0.02 * 0.02 + 0.02 * 0.02) / 12.0 + m_box * 0.12 * 0.12); // boxes at (0, +-r)
    for kind in BackendKind::available() {
        let p = backend(kind).mass_properties();
        assert!((p.mass - mass).abs() < 1e-12 * mass, "{kind}: mass {}", p.mass);
        assert!(
            (p.inertia[2][2] - izz).abs() < 1e-12 * izz,
            "{kind}: Izz {} vs {izz}",
            p.inertia[2][2]
        );
        assert!(
            p.center.iter().all(|c| c.abs() < 1e-15),
            "{kind}: centre {:?}",
            p.center
        );
        if kind != BackendKind::Rapier {
            assert!(
                (p.inertia[0][0] - ixx).abs() < 1e-12,
                "{kind}: Ixx {} vs {ixx}",
                p.inertia[0][0]
            );
            assert!((p.inertia[1][1] - ixx).abs() < 1e-12, "{kind}: Iyy {}", p.inertia[1][1]);
        }
    }
}

#[test]
fn constant_thrust_from_rest_follows_semi_implicit_euler() {
    // u0 = u2 = 1: force 2 N along body +x, no torque. ODE's dWorldStep is
    // semi-implicit Euler: v_n = n a dt and x_n = a dt^2 n (n + 1) / 2,
    // i.e. x = a t^2 / 2 plus the integrator's known error a t dt / 2.
    let (mass, _) = hand_mass_and_izz();
    let a = 2.0 / mass;
    let dt = StepSettings::default().dt;
    for kind in BackendKind::available() {
        let mut b = backend(kind);
        for n in 1..=500u32 {
            b.step(&[1.0, 0.0, 1.0, 0.0]).unwrap();
            let s = b.state();
            let n = n as f64;
            let x = a * dt * dt * n * (n + 1.0) / 2.0;
            assert!(
                (s.x - x).abs() <= 1e-12 * x.max(1.0),
                "{kind} step {n}: x {} vs {x}",
                s.x
            );
            assert!((s.vx - a * dt * n).abs() <= 1e-12, "{kind}: vx {}", s.vx);
            assert_eq!(
                (s.y, s.vy, s.omega, s.heading),
                (0.0, 0.0, 0.0, 0.0),
                "{kind}: left the x axis"
            );
            let t = n * dt;
            assert!(
                (s.x - a * t * t / 2.0 - a * t * dt / 2.0).abs() < 1e-12,
                "{kind}: closed form"
            );
        }
    }
}

#[test]
fn free_spin_keeps_omega_and_turns_by_the_integrators_rule() {
    let dt = StepSettings::default().dt;
    for kind in BackendKind::available() {
        let mut b = backend(kind);
        b.reset(&BodyState {
            omega: 1.0,
            ..BodyState::default()
        })
        .unwrap();
        for n in 1..=400u32 {
            b.step(&[0.0; 4]).unwrap();
            let s = b.state();
            // ODE's implicit gyroscopic term rounds omega by an ulp at times
            // (exactly constant without it: see the next test).
            assert!(
                (s.omega - 1.0).abs() < 1e-12,
                "{kind}: omega changed without torque: {}",
                s.omega
            );
            assert_eq!((s.x, s.y, s.vx, s.vy), (0.0, 0.0, 0.0, 0.0), "{kind}: drifted");
            // ODE (and native) advance 2 atan(w dt / 2) per step, rapier atan(w dt).
            let per_step = if kind == BackendKind::Rapier {
                dt.atan()
            } else {
                2.0 * (dt / 2.0).atan()
            };
            let expected = wrap_angle(n as f64 * per_step);
            assert!(
                wrap_angle(s.heading - expected).abs() < 1e-10,
                "{kind} step {n}: {} vs {expected}",
                s.heading
            );
        }
        // And it is close to the exact w t: the rule's error is (w dt)^3 / 12 per step.
        let exact = wrap_angle(400.0 * dt);
        assert!(wrap_angle(b.state().heading - exact).abs() < 400.0 * dt.powi(3) / 2.0);
    }
}

#[test]
fn free_spin_is_exact_in_ode_without_its_gyroscopic_term() {
    let model = BodySettings::default().model().unwrap();
    let settings = StepSettings {
        ode_gyroscopic: false,
        ..StepSettings::default()
    };
    let mut b = create_backend(BackendKind::Ode, &model, &settings).unwrap();
    b.reset(&BodyState {
        omega: 1.0,
        ..BodyState::default()
    })
    .unwrap();
    for _ in 0..500 {
        b.step(&[0.0; 4]).unwrap();
        assert_eq!(b.state().omega, 1.0);
    }
}

#[test]
fn thruster_table_pins_directions_and_torques() {
    for kind in BackendKind::available() {
        // u0 = u2: pure body +x, no spin.
        let mut b = backend(kind);
        b.step(&[0.6, 0.0, 0.6, 0.0]).unwrap();
        let s = b.state();
        assert!(s.vx > 0.0 && s.vy == 0.0 && s.omega == 0.0, "{kind} u0=u2: {s:?}");
        // u1 = u3: pure body +y, no spin.
        let mut b = backend(kind);
        b.step(&[0.0, 0.8, 0.0, 0.8]).unwrap();
        let s = b.state();
        assert!(s.vy > 0.0 && s.vx == 0.0 && s.omega == 0.0, "{kind} u1=u3: {s:?}");
        // u0 alone: anticlockwise spin and a drift towards +x.
        let mut b = backend(kind);
        b.step(&[1.0, 0.0, 0.0, 0.0]).unwrap();
        let s = b.state();
        assert!(s.omega > 0.0 && s.vx > 0.0, "{kind} u0: {s:?}");
        // u1 alone: anticlockwise; u2, u3 alone: clockwise.
        for (thrust, sign) in [
            ([0.0, 1.0, 0.0, 0.0], 1.0),
            ([0.0, 0.0, 1.0, 0.0], -1.0),
            ([0.0, 0.0, 0.0, 1.0], -1.0),
        ] {
            let mut b = backend(kind);
            b.step(&thrust).unwrap();
            assert!(b.state().omega * sign > 0.0, "{kind} {thrust:?}: {:?}", b.state());
        }
        // Torque of one thruster: r F / Izz per second.
        let (_, izz) = hand_mass_and_izz();
        let dt = StepSettings::default().dt;
        let mut b = backend(kind);
        b.step(&[1.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(
            (b.state().omega - 0.12 * dt / izz).abs() < 1e-12,
            "{kind}: omega {}",
            b.state().omega
        );
    }
}

#[test]
fn body_thrust_turns_with_the_body() {
    // Heading pi/2 (body +x points to world +y): u0 = u2 pushes towards world +y.
    for kind in BackendKind::available() {
        let mut b = backend(kind);
        b.reset(&BodyState {
            heading: PI / 2.0,
            ..BodyState::default()
        })
        .unwrap();
        b.step(&[1.0, 0.0, 1.0, 0.0]).unwrap();
        let s = b.state();
        assert!(s.vy > 0.0 && s.vx.abs() < 1e-15 && s.omega == 0.0, "{kind}: {s:?}");
    }
}
