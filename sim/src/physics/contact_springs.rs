//! Gazebo's soft contacts (`<gazebo reference="LINK"><kp>`, N/m) where they decide who carries
//! the weight. ODE lets a contact of stiffness kp sink by its force over kp, so when several
//! contacts share one weight (TIAGo's two wheels and four casters, all their bottoms at one
//! height) the stiffer ones carry it: PAL gives the casters kp = 1e6 and leaves the wheels at
//! ODE's far stiffer default, and in Gazebo the wheels carry the base. Rapier holds every
//! contact equally hard and splits a shared weight as its solver's iterations leave it (TIAGo's
//! casters took 90% of it, and the wheels could not brake the base).
//!
//! rover gives a `<kp>` link's contacts way by the most their spring could sink: the robot's
//! whole weight over kp (TIAGo's casters: 0.64 mm). Through rapier's contact modification hook
//! its contacts start pushing only that far in, so the stiffer contacts beside it carry the
//! load first, and it takes its share once they have given way (the base pitching onto a
//! caster as it brakes). A robot whose contacts all have a `<kp>` of one size (TurtleBot3's
//! 5e5 and 1e6 N/m on a 1 kg robot: 0.02 mm) is all but unchanged.

use std::collections::HashMap;

use rapier3d::prelude::*;

/// The colliders whose contacts give way, and by how much (m).
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactSprings {
    give_m: HashMap<ColliderHandle, f32>,
}

impl ContactSprings {
    /// Lets `collider`'s contacts give way by `weight_n` over `kp_n_per_m`.
    pub(crate) fn insert(&mut self, collider: ColliderHandle, kp_n_per_m: f32, weight_n: f32) {
        if kp_n_per_m > 0.0 && weight_n > 0.0 {
            self.give_m.insert(collider, weight_n / kp_n_per_m);
        }
    }

    /// Whether no collider gives way.
    pub(crate) fn is_empty(&self) -> bool {
        self.give_m.is_empty()
    }
}

impl PhysicsHooks for ContactSprings {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        // Two soft surfaces give way together (springs in series).
        let give_m = self.give_m.get(&context.collider1).copied().unwrap_or(0.0)
            + self.give_m.get(&context.collider2).copied().unwrap_or(0.0);
        if give_m <= 0.0 {
            return;
        }
        if let Some(rigid) = context.rigid_mut() {
            for contact in rigid.solver_contacts.iter_mut() {
                contact.dist += give_m;
            }
        }
    }
}
