//! ODE worlds, bodies and joints as owned values.
//!
//! A [`Body`] or [`Joint`] keeps its world alive through a shared handle, so
//! it is always destroyed before the world that owns it. The handles are not
//! `Send`: an ODE world lives and dies on the thread that made it, which is
//! the "one world per thread" rule.

use std::rc::Rc;

use super::error::{check_finite, check_positive};
use super::{ensure_thread_ready, Mass, OdeError};

struct WorldHandle {
    id: ode_sys::dWorldID,
    threading: ode_sys::dThreadingImplementationID,
}

impl Drop for WorldHandle {
    fn drop(&mut self) {
        // SAFETY: every body and joint holds an Rc to this handle, so none
        // is left; detach the private threading implementation, destroy the
        // world, then free the implementation, in the order ODE requires.
        unsafe {
            ode_sys::dWorldSetStepThreadingImplementation(self.id, std::ptr::null(), std::ptr::null_mut());
            ode_sys::dWorldDestroy(self.id);
            ode_sys::dThreadingFreeImplementation(self.threading);
        }
    }
}

/// An ODE world with its own self-threaded threading implementation (ODE's
/// shared default crashes when worlds step concurrently) and zero gravity.
pub struct World {
    handle: Rc<WorldHandle>,
}

impl World {
    /// Creates a world; initialises ODE and this thread's ODE data first.
    pub fn new() -> Result<World, OdeError> {
        ensure_thread_ready()?;
        // SAFETY: ODE is initialised and this thread has its ODE data.
        let id = unsafe { ode_sys::dWorldCreate() };
        if id.is_null() {
            return Err(OdeError::CallFailed { call: "dWorldCreate" });
        }
        // SAFETY: as above.
        let threading = unsafe { ode_sys::dThreadingAllocateSelfThreadedImplementation() };
        if threading.is_null() {
            // SAFETY: `id` is a live world with nothing attached.
            unsafe { ode_sys::dWorldDestroy(id) };
            return Err(OdeError::CallFailed {
                call: "dThreadingAllocateSelfThreadedImplementation",
            });
        }
        // SAFETY: `id` and `threading` are live; the functions table
        // belongs to `threading`, which outlives the attachment (see Drop).
        unsafe {
            let functions = ode_sys::dThreadingImplementationGetFunctions(threading);
            ode_sys::dWorldSetStepThreadingImplementation(id, functions, threading);
            ode_sys::dWorldSetGravity(id, 0.0, 0.0, 0.0);
        }
        Ok(World {
            handle: Rc::new(WorldHandle { id, threading }),
        })
    }

    /// Sets gravity (m/s^2).
    pub fn set_gravity(&self, gravity: [f64; 3]) -> Result<(), OdeError> {
        let [x, y, z] = check_finite("gravity", gravity)?;
        // SAFETY: the world is live; the vector is finite.
        unsafe { ode_sys::dWorldSetGravity(self.handle.id, x, y, z) };
        Ok(())
    }

    /// Sets the number of iterations of `dWorldQuickStep` (>= 1).
    pub fn set_quick_step_iterations(&self, iterations: u32) -> Result<(), OdeError> {
        if iterations == 0 || iterations > i32::MAX as u32 {
            return Err(OdeError::invalid("QuickStep iterations", iterations, "must be >= 1"));
        }
        // SAFETY: the world is live; the count is a positive int.
        unsafe { ode_sys::dWorldSetQuickStepNumIterations(self.handle.id, iterations as i32) };
        Ok(())
    }

    /// Advances the world by `dt` seconds with ODE's exact `dWorldStep`.
    pub fn step(&self, dt: f64) -> Result<(), OdeError> {
        // dWorldStep asserts dt > 0.
        self.step_prechecked(check_positive("time step dt", dt)?)
    }

    /// [`World::step`] without re-checking `dt`, for a caller that checked
    /// it once when it was set (`OdeBackend` validates its `StepSettings` at
    /// construction and never changes them). A `dt <= 0` or NaN here would
    /// not be undefined behaviour but would make ODE abort the process, hence
    /// crate-private, with the check kept in debug builds.
    #[inline]
    pub(crate) fn step_prechecked(&self, dt: f64) -> Result<(), OdeError> {
        debug_assert!(dt.is_finite() && dt > 0.0, "time step dt {dt} must be finite and > 0");
        // SAFETY: the world is live; the caller guarantees dt > 0.
        let ok = unsafe { ode_sys::dWorldStep(self.handle.id, dt) };
        if ok == 0 {
            return Err(OdeError::CallFailed { call: "dWorldStep" });
        }
        Ok(())
    }

    /// [`World::quick_step`] without re-checking `dt`; see [`World::step_prechecked`].
    #[inline]
    pub(crate) fn quick_step_prechecked(&self, dt: f64) -> Result<(), OdeError> {
        debug_assert!(dt.is_finite() && dt > 0.0, "time step dt {dt} must be finite and > 0");
        // SAFETY: the world is live; the caller guarantees dt > 0.
        let ok = unsafe { ode_sys::dWorldQuickStep(self.handle.id, dt) };
        if ok == 0 {
            return Err(OdeError::CallFailed {
                call: "dWorldQuickStep",
            });
        }
        Ok(())
    }

    /// Advances the world by `dt` seconds with ODE's iterative `dWorldQuickStep`.
    pub fn quick_step(&self, dt: f64) -> Result<(), OdeError> {
        // dWorldQuickStep asserts dt > 0.
        self.quick_step_prechecked(check_positive("time step dt", dt)?)
    }

    /// Creates a dynamic body at the origin, at rest, with ODE's default mass.
    pub fn create_body(&self) -> Result<Body, OdeError> {
        // SAFETY: the world is live.
        let id = unsafe { ode_sys::dBodyCreate(self.handle.id) };
        if id.is_null() {
            return Err(OdeError::CallFailed { call: "dBodyCreate" });
        }
        Ok(Body {
            id,
            _world: Rc::clone(&self.handle),
        })
    }

    /// Creates a Plane2D joint that holds `body` in the world's x-y plane.
    pub fn create_plane2d_joint(&self, body: &Body) -> Result<Joint, OdeError> {
        if !Rc::ptr_eq(&self.handle, &body._world) {
            return Err(OdeError::invalid(
                "body",
                "a body of another world",
                "must belong to this world",
            ));
        }
        // SAFETY: the world is live; a null group means "no joint group".
        let id = unsafe { ode_sys::dJointCreatePlane2D(self.handle.id, std::ptr::null_mut()) };
        if id.is_null() {
            return Err(OdeError::CallFailed {
                call: "dJointCreatePlane2D",
            });
        }
        // SAFETY: joint and body are live and belong to the same world; a
        // null second body attaches the joint to the static environment.
        unsafe { ode_sys::dJointAttach(id, body.id, std::ptr::null_mut()) };
        Ok(Joint {
            id,
            _world: Rc::clone(&self.handle),
        })
    }
}

/// A rigid body of a [`World`], destroyed on drop.
pub struct Body {
    id: ode_sys::dBodyID,
    _world: Rc<WorldHandle>,
}

impl Drop for Body {
    fn drop(&mut self) {
        // SAFETY: the Rc keeps the world alive, so the body is still live.
        unsafe { ode_sys::dBodyDestroy(self.id) };
    }
}

#[inline]
fn copy3(ptr: *const f64) -> [f64; 3] {
    // SAFETY: callers pass a pointer ODE returned for a live body, which
    // points at (at least) 3 consecutive dReal values.
    unsafe { [*ptr, *ptr.add(1), *ptr.add(2)] }
}

impl Body {
    /// Sets the body's mass after the checks `dBodySetMass` would abort on.
    pub fn set_mass(&self, mass: &Mass) -> Result<(), OdeError> {
        mass.validate_for_body()?;
        // SAFETY: the body is live; the mass passed ODE's own checks above.
        unsafe { ode_sys::dBodySetMass(self.id, mass.raw()) };
        Ok(())
    }

    /// The body's mass as ODE stores it.
    pub fn mass(&self) -> Mass {
        let mut raw = ode_sys::dMass::default();
        // SAFETY: the body is live; `raw` is a dMass for ODE to overwrite.
        unsafe { ode_sys::dBodyGetMass(self.id, &mut raw) };
        Mass::from_raw(raw)
    }

    /// Sets the position of the body's origin (its centre of mass).
    pub fn set_position(&self, position: [f64; 3]) -> Result<(), OdeError> {
        let [x, y, z] = check_finite("position", position)?;
        // SAFETY: the body is live; the values are finite.
        unsafe { ode_sys::dBodySetPosition(self.id, x, y, z) };
        Ok(())
    }

    /// Sets the orientation quaternion (w, x, y, z); ODE normalises it.
    pub fn set_quaternion(&self, q: [f64; 4]) -> Result<(), OdeError> {
        let q = check_finite("quaternion", q)?;
        if q.iter().map(|v| v * v).sum::<f64>() == 0.0 {
            return Err(OdeError::invalid("quaternion", q, "must not be zero"));
        }
        // SAFETY: the body is live; the quaternion is finite and non-zero.
        unsafe { ode_sys::dBodySetQuaternion(self.id, q.as_ptr()) };
        Ok(())
    }

    /// Sets the linear velocity (m/s).
    pub fn set_linear_velocity(&self, v: [f64; 3]) -> Result<(), OdeError> {
        let [x, y, z] = check_finite("linear velocity", v)?;
        // SAFETY: the body is live; the values are finite.
        unsafe { ode_sys::dBodySetLinearVel(self.id, x, y, z) };
        Ok(())
    }

    /// Sets the angular velocity (rad/s).
    pub fn set_angular_velocity(&self, w: [f64; 3]) -> Result<(), OdeError> {
        let [x, y, z] = check_finite("angular velocity", w)?;
        // SAFETY: the body is live; the values are finite.
        unsafe { ode_sys::dBodySetAngularVel(self.id, x, y, z) };
        Ok(())
    }

    /// Position of the body's origin.
    #[inline]
    pub fn position(&self) -> [f64; 3] {
        // SAFETY: the body is live; ODE returns a pointer to its dVector3.
        copy3(unsafe { ode_sys::dBodyGetPosition(self.id) })
    }

    /// Orientation quaternion (w, x, y, z).
    #[inline]
    pub fn quaternion(&self) -> [f64; 4] {
        // SAFETY: the body is live; ODE returns a pointer to its dQuaternion.
        let q = unsafe { ode_sys::dBodyGetQuaternion(self.id) };
        // SAFETY: a dQuaternion is 4 consecutive dReal values.
        unsafe { [*q, *q.add(1), *q.add(2), *q.add(3)] }
    }

    /// Linear velocity.
    #[inline]
    pub fn linear_velocity(&self) -> [f64; 3] {
        // SAFETY: the body is live; ODE returns a pointer to its dVector3.
        copy3(unsafe { ode_sys::dBodyGetLinearVel(self.id) })
    }

    /// Angular velocity.
    #[inline]
    pub fn angular_velocity(&self) -> [f64; 3] {
        // SAFETY: the body is live; ODE returns a pointer to its dVector3.
        copy3(unsafe { ode_sys::dBodyGetAngularVel(self.id) })
    }

    /// Adds a force given in the body frame at a point given in the body
    /// frame (relative to the body origin). ODE clears accumulated forces
    /// after each step.
    pub fn add_rel_force_at_rel_pos(&self, force: [f64; 3], point: [f64; 3]) -> Result<(), OdeError> {
        let force = check_finite("force", force)?;
        let point = check_finite("force application point", point)?;
        self.add_rel_force_at_rel_pos_prechecked(force, point);
        Ok(())
    }

    /// [`Body::add_rel_force_at_rel_pos`] without re-checking the values, for
    /// a caller that has proved them finite (`OdeBackend`: a finite force at
    /// full command, from a validated model, times a thrust that
    /// `validate_thrust` put in [0, 1], at a finite precomputed arm). A
    /// non-finite value here would not be undefined behaviour (ODE only does
    /// arithmetic with it) but would turn the state into NaN and make a later
    /// step abort the process, hence crate-private, with the check kept in
    /// debug builds.
    #[inline]
    pub(crate) fn add_rel_force_at_rel_pos_prechecked(&self, force: [f64; 3], point: [f64; 3]) {
        debug_assert!(
            force.iter().chain(&point).all(|v| v.is_finite()),
            "force {force:?} at {point:?} must be finite"
        );
        let ([fx, fy, fz], [px, py, pz]) = (force, point);
        // SAFETY: the body is live; ODE accepts any values here, and finite
        // ones (the caller's guarantee) keep the body's state finite.
        unsafe { ode_sys::dBodyAddRelForceAtRelPos(self.id, fx, fy, fz, px, py, pz) };
    }

    /// The raw ODE id of the body, for [`super::bare`] (the benchmark
    /// reference) only. Valid while `self` lives.
    pub(crate) fn raw_id(&self) -> ode_sys::dBodyID {
        self.id
    }

    /// The raw ODE id of the body's world, for [`super::bare`] only. Valid
    /// while `self` lives (the body keeps its world alive).
    pub(crate) fn raw_world_id(&self) -> ode_sys::dWorldID {
        self._world.id
    }

    /// ODE's gyroscopic term (on by default).
    pub fn set_gyroscopic_mode(&self, enabled: bool) {
        // SAFETY: the body is live.
        unsafe { ode_sys::dBodySetGyroscopicMode(self.id, enabled as i32) };
    }

    /// ODE's finite rotation mode (off by default: infinitesimal quaternion
    /// update, which advances a planar angle by 2 atan(w dt / 2)).
    pub fn set_finite_rotation_mode(&self, enabled: bool) {
        // SAFETY: the body is live.
        unsafe { ode_sys::dBodySetFiniteRotationMode(self.id, enabled as i32) };
    }
}

/// A joint of a [`World`], destroyed on drop.
pub struct Joint {
    id: ode_sys::dJointID,
    _world: Rc<WorldHandle>,
}

impl Drop for Joint {
    fn drop(&mut self) {
        // SAFETY: the Rc keeps the world alive, so the joint is still live.
        unsafe { ode_sys::dJointDestroy(self.id) };
    }
}
