// Free bodies stepped without ODE's world step (ode_engine.hpp): QuickStep's arithmetic for a body
// that no constraint holds, to the bit.
//
// For an island of one body and no joint, dWorldQuickStep adds gravity to the force accumulator,
// the implicit gyroscopic torque (Lacoursière 2006) to the torque accumulator (quickstep.cpp,
// stage 0), updates the velocities from both (stage 6a), then moves the body with dxStepBody and
// clears the accumulators (stage 6b). What it spends around that — a memory arena per world and
// step, the islands built, the stages posted to its threading implementation — costs more than
// the arithmetic for a world of one or a few bodies. The same arithmetic here, with ODE's own
// inline matrix helpers (ode/odemath.h) and its exported rotation functions, gives the same bits;
// ode_engine_test.cpp checks that against dWorldQuickStep over thousands of steps.
#include "engines/ode/ode_engine.hpp"

#include <ode/odemath.h>
#include <ode/rotation.h>

#include <ssx/error.hpp>

#include <cstring>
#include <string>

namespace ssx::detail {

namespace {

// the accumulators and state ODE keeps for a body, writable (ODE hands them out read-only)
dReal* writable(const dReal* p) { return const_cast<dReal*>(p); }

}  // namespace

bool odeBodyIsPlain(dBodyID b) {
  // what dxStepBody would do more than the plain step: no damping, no finite rotation, no cap on
  // the angular speed; gravity on; enabled (ssx sets none of these: checked so that it stays so)
  return dBodyIsEnabled(b) != 0 && dBodyGetFiniteRotationMode(b) == 0 && dBodyGetLinearDamping(b) == 0 &&
         dBodyGetAngularDamping(b) == 0 && dBodyGetMaxAngularSpeed(b) == dInfinity && dBodyGetGravityMode(b) != 0;
}

void odeInverseInertia(const dMass& mass, bool kinematic, dReal* inv_inertia, dReal& inv_mass) {
  // as dBodySetMass computes them (dBodySetKinematic zeroes both)
  std::memset(inv_inertia, 0, 12 * sizeof(dReal));
  if (kinematic) {
    inv_mass = 0;
    return;
  }
  if (dInvertPDMatrix(mass.I, inv_inertia, 3) == 0) dRSetIdentity(inv_inertia);
  inv_mass = dRecip(mass.mass);
}

void stepFreeOdeBody(dBodyID b, const dMass& mass, const dReal* inv_inertia, dReal inv_mass, bool gyroscopic,
                     const dReal* gravity, dReal h) {
  dReal* const facc = writable(dBodyGetForce(b));
  dReal* const tacc = writable(dBodyGetTorque(b));
  dReal* const pos = writable(dBodyGetPosition(b));
  dReal* const q = writable(dBodyGetQuaternion(b));
  dReal* const R = writable(dBodyGetRotation(b));
  dReal* const lvel = writable(dBodyGetLinearVel(b));
  dReal* const avel = writable(dBodyGetAngularVel(b));

  // stage 0: gravity (each axis only when it is not zero, as ODE does)
  for (int k = 0; k < 3; ++k)
    if (gravity[k] != 0) facc[k] += mass.mass * gravity[k];
  // the inverse inertia in the world frame
  dMatrix3 tmp, inv_world;
  dMultiply2_333(tmp, inv_inertia, R);
  dMultiply0_333(inv_world, R, tmp);
  // the implicit gyroscopic torque
  if (gyroscopic && inv_mass > 0) {
    dMatrix3 I;
    dMultiply2_333(tmp, mass.I, R);
    dMultiply0_333(I, R, tmp);
    dVector3 L;
    dMultiply0_331(L, I, avel);
    dMatrix3 Itild = {0};
    dSetCrossMatrixMinus(Itild, L, 4);
    for (int ii = 0; ii < 12; ++ii) Itild[ii] = Itild[ii] * h + I[ii];
    dScaleVector3(L, dRecip(h));
    dMatrix3 itInv;
    if (dInvertMatrix3(itInv, Itild) != 0) {
      dMultiply0_333(Itild, I, itInv);
      Itild[0] -= 1;
      Itild[5] -= 1;
      Itild[10] -= 1;
      dVector3 tau0;
      dMultiply0_331(tau0, Itild, L);
      dAddVectors3(tacc, tacc, tau0);
    }
  }
  // stage 6a: the velocities
  const dReal invmass_h = h * inv_mass;
  for (int j = 0; j < 3; ++j) {
    lvel[j] += invmass_h * facc[j];
    tacc[j] *= h;
  }
  dMultiplyAdd0_331(avel, inv_world, tacc);
  // stage 6b: dxStepBody, the infinitesimal rotation, then the accumulators cleared
  for (int j = 0; j < 3; ++j) pos[j] += h * lvel[j];
  dReal dq[4];
  dDQfromW(dq, avel, q);
  for (int j = 0; j < 4; ++j) q[j] += h * dq[j];
  dNormalize4(q);
  dQtoR(q, R);
  dZeroVector3(facc);
  dZeroVector3(tacc);
}

// the engine's side of it: which bodies are free, and the partitions' step around ODE's

void OdeEngine::cacheFreeStep(Body& body) {
  // (a body out of the world stays so in whichever ODE body holds it now: moveBody makes another)
  if (!body.enabled) dBodyDisable(body.id);
  odeInverseInertia(body.mass, body.kinematic, body.inv_inertia, body.inv_mass);
  body.gyroscopic = dBodyGetGyroscopicMode(body.id) != 0;
  body.plain = odeBodyIsPlain(body.id);
}

void OdeEngine::setEnabled(int index, bool enabled) {
  if (index < 0 || static_cast<std::size_t>(index) >= bodies_.size())
    throw Error("ode: setEnabled: no body " + std::to_string(index));
  Body& body = bodies_[static_cast<std::size_t>(index)];
  body.enabled = enabled;
  if (enabled) {
    // (what was added to it while it was out is not applied)
    dBodySetForce(body.id, 0, 0, 0);
    dBodySetTorque(body.id, 0, 0, 0);
    dBodyEnable(body.id);
  }
  cacheFreeStep(body);
}

void OdeEngine::stepPartition(Partition& p, double h, std::span<const Wrench> wrenches) {
  if (p.order.empty()) return;
  // ODE clears force accumulators after each step: apply the held wrenches every substep
  std::size_t out = 0;  // bodies out of the world: nothing moves them
  for (const int i : p.order) {
    const Wrench& w = wrenches[static_cast<std::size_t>(i)];
    const Body& body = bodies_[static_cast<std::size_t>(i)];
    if (!body.enabled) {
      ++out;
      continue;
    }
    dBodyAddForce(body.id, w.force.x(), w.force.y(), w.force.z());
    dBodyAddTorque(body.id, w.torque.x(), w.torque.y(), w.torque.z());
  }
  // the bodies no constraint holds are stepped here, not by ODE (see ode_engine.hpp)
  std::size_t free = 0;
  for (const int i : p.order) free += isFree(bodies_[static_cast<std::size_t>(i)]) ? 1 : 0;
  if (free + out == p.order.size()) {
    stepFree(p, h);
    return;
  }
  auto each_free = [&](auto&& f) {
    for (const int i : p.order)
      if (isFree(bodies_[static_cast<std::size_t>(i)])) f(bodies_[static_cast<std::size_t>(i)].id);
  };
  if (free > 0) each_free([](dBodyID b) { dBodyDisable(b); });  // (an ODE error after this poisons the engine)
  solveWithOde(p, h);
  if (free > 0) {
    each_free([](dBodyID b) { dBodyEnable(b); });
    stepFree(p, h);
  }
}

void OdeEngine::stepFree(Partition& p, double h) {
  for (const int i : p.order) {
    const Body& body = bodies_[static_cast<std::size_t>(i)];
    if (isFree(body))
      stepFreeOdeBody(body.id, body.mass, body.inv_inertia, body.inv_mass, body.gyroscopic, gravity_, h);
  }
}

}  // namespace ssx::detail
