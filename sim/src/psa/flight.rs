//! The steps of a trial, written once for the scalar path ([`super::trial`],
//! one body in its own world) and the ODE lockstep path
//! ([`super::ode_lockstep`], a fleet of bodies in one world): each network
//! reads its sensors, acts, the world steps every body, and each network
//! scores the step. The two paths differ only in the world they step, so
//! their arithmetic is the same by construction.

use super::step::{score, sense, Reading};
use super::trial::TrialRecord;
use super::{PsaError, PsaSettings, Target, INPUT_COUNT, THRUSTER_COUNT};
use crate::numeric::{clamp_unit, NoiseSource};
use crate::physics::{OdeFleet, PhysicsBackend, PhysicsError, PlanarState};
use esp_neuroevolution::network::Network;

/// Bodies that step together: body `l` is flown by lane `l`.
pub(crate) trait World {
    /// Applies `thrust[l]` to body `l` and advances every body one step.
    fn step(&mut self, thrust: &[[f64; THRUSTER_COUNT]]) -> Result<(), PhysicsError>;
    /// Body `l`'s state in the plane.
    fn planar_state(&self, l: usize) -> PlanarState<f64>;
}

/// One body in its own world (the scalar path).
impl World for dyn PhysicsBackend + '_ {
    #[inline(always)]
    fn step(&mut self, thrust: &[[f64; THRUSTER_COUNT]]) -> Result<(), PhysicsError> {
        PhysicsBackend::step(self, &thrust[0])
    }

    #[inline(always)]
    fn planar_state(&self, _: usize) -> PlanarState<f64> {
        PhysicsBackend::planar_state(self)
    }
}

/// Every body of an ODE world (the lockstep path).
impl World for OdeFleet {
    #[inline(always)]
    fn step(&mut self, thrust: &[[f64; THRUSTER_COUNT]]) -> Result<(), PhysicsError> {
        OdeFleet::step(self, thrust)
    }

    #[inline(always)]
    fn planar_state(&self, l: usize) -> PlanarState<f64> {
        OdeFleet::planar_state(self, l)
    }
}

/// One network's trial: what a flight keeps between steps.
pub(crate) struct Lane<'n> {
    network: &'n Network,
    target: [f64; 3],
    noise: NoiseSource<u64>,
    state: PlanarState<f64>,
    /// What the controller read last (set when the flight starts).
    reading: Reading<f64>,
    /// The points of the steps flown so far.
    pub(crate) points: f64,
}

impl<'n> Lane<'n> {
    /// A lane at the start of its trial, its body in `state`.
    pub(crate) fn new(
        network: &'n Network,
        target: &Target,
        noise: NoiseSource<u64>,
        state: PlanarState<f64>,
    ) -> Lane<'n> {
        Lane {
            network,
            target: [target.x, target.y, target.heading],
            noise,
            state,
            reading: Reading {
                inputs: [0.0; INPUT_COUNT],
                heading_error: 0.0,
            },
            points: 0.0,
        }
    }

    /// What the controller reads of the lane's state now.
    #[inline(always)]
    fn read<const NOISY: bool>(&mut self, s: &PsaSettings) -> Reading<f64> {
        let state = &self.state;
        sense::<f64, NOISY>(
            s.step(),
            state.position,
            state.velocity,
            state.heading(),
            state.omega,
            self.target,
            &mut self.noise,
        )
    }
}

/// The steps of one trial of every lane, body `l` of `world` flown by
/// `lanes[l]` from its current state, with input and output noise if
/// `NOISY`; the points add up in the lanes. With `record` (which already
/// holds the start) every step of lane 0 is recorded: a flight of one lane.
#[inline(always)]
pub(crate) fn fly_steps<const NOISY: bool, W: World + ?Sized>(
    s: &PsaSettings,
    world: &mut W,
    lanes: &mut [Lane<'_>],
    mut record: Option<&mut TrialRecord>,
) -> Result<(), PsaError> {
    debug_assert!(
        record.is_none() || lanes.len() == 1,
        "a record is of a flight of one lane"
    );
    let mut outputs = vec![[0.0; THRUSTER_COUNT]; lanes.len()];
    for lane in lanes.iter_mut() {
        lane.reading = lane.read::<NOISY>(s);
    }
    for _ in 0..s.steps {
        for (lane, out) in lanes.iter_mut().zip(&mut outputs) {
            lane.network.activate_with(s.exponential, &lane.reading.inputs, out);
            if NOISY {
                s.noise.perturb_outputs(out, &mut lane.noise);
            }
            for u in out.iter_mut() {
                *u = clamp_unit(*u);
            }
        }
        world.step(&outputs)?;
        for (l, lane) in lanes.iter_mut().enumerate() {
            let previous_omega = lane.state.omega;
            lane.state = world.planar_state(l);
            let next = lane.read::<NOISY>(s);
            let state = &lane.state;
            let step_points = score(
                s.step(),
                &next,
                &lane.reading,
                state.position,
                state.omega,
                previous_omega,
                lane.target,
            );
            lane.reading = next;
            lane.points += step_points;
            if let Some(r) = record.as_deref_mut() {
                r.states.push(state.to_body_state());
                r.outputs.push(outputs[l]);
                r.points.push(step_points);
            }
        }
    }
    Ok(())
}
