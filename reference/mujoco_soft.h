// MuJoCo's soft contact as rbx sets it (negative solref: stiffness and damping per unit
// effective mass): the map from a contact duration and a restitution to those two numbers.
#pragma once

namespace rbx {

/// Stiffness (1/s^2, per unit effective mass) for a contact lasting `steps` steps when undamped.
double contact_stiffness(double dt, double steps);

/// Restitution of one soft contact as MuJoCo integrates it, at damping ratio `zeta`, entering at
/// `entry_phase` (0..1) of a step, lasting `steps` steps when undamped.
double soft_contact_restitution(double zeta, double entry_phase, double steps);

/// Damping ratio that makes MuJoCo's soft contact return restitution `e` (capped where the
/// explicit damping would overshoot).
double restitution_damping_ratio(double e, double steps);

}  // namespace rbx
