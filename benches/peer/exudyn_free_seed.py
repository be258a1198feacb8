#!/usr/bin/env python3
"""The free seed in Exudyn: the peer of mechgen's forward dynamics, measured side by side.

The piston-crank of `examples/scenes/piston_crank_free.mech` (the seed of
`/work/shared/seed-model.md` with the mass properties of `piston_crank_dynamics.mech`; mm, kg,
s; gravity (0, -9810) mm/s^2), its crank free, released from rest at crank angle 0.3 rad, built
from Exudyn's 2D rigid bodies (NodeRigidBody2D + ObjectRigidBody2D, reference point at the
centre of mass), revolute joints (ObjectJointRevolute2D) and a prismatic joint
(ObjectJointPrismatic2D, which also locks the piston's rotation), integrated by Exudyn's
implicit generalized-alpha solver (index 3, its default) at a fixed step.

Prints, per run:
  * wall time per step of Exudyn's `SolveSteps` (the stepping loop alone: building the system,
    `InitializeSolver` with its initial accelerations and `FinalizeSolver` are not timed),
    the median and the fastest over several repetitions;
  * the crank angle at t = 0.1, 0.2, ..., 0.5 s against an independent reference: the seed's
    reduced one-coordinate Lagrange equation with its closed-form kinematics, integrated with
    scipy's DOP853 at rtol = atol = 1e-12 (or a classical RK4 at a fine step without scipy).

The reference needs only numpy/scipy (or pure python); `--reference-only` runs it without
Exudyn. See `benches/peer/README.md` for the commands and the measured figures.
"""

import argparse
import math
import statistics
import sys
import time

# ----------------------------------------------------------------------------------------------
# The seed: geometry (mm) and mass properties (kg, kg mm^2), as in piston_crank_dynamics.mech.
# ----------------------------------------------------------------------------------------------
CRANK_RADIUS = 43.0  # crank pin on the crank at (0, 43)
ROD_PIN_CRANK = (41.3, 0.0)  # crank pin on the rod
ROD_PIN_PISTON = (0.0, 102.6)  # piston pin on the rod
PISTON_PIN = (-28.0, 0.0)  # piston pin on the piston
LINER = (156.8, 0.0)  # liner (ground) reference point; the slide is along its x axis
ROD_LENGTH = math.hypot(102.6 - 0.0, 0.0 - 41.3)  # pin-to-pin distance on the rod
GRAVITY = -9810.0  # mm/s^2, along y

MASS = {"piston": 0.5, "rod": 0.4, "crank": 1.2}
INERTIA = {"piston": 300.0, "rod": 1500.0, "crank": 2000.0}

PHI0 = 0.3  # crank angle at release (rad), from rest
T_END = 0.5
REPORT_TIMES = [0.1, 0.2, 0.3, 0.4, 0.5]


def rot(theta, v):
    c, s = math.cos(theta), math.sin(theta)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


# ----------------------------------------------------------------------------------------------
# Closed-form kinematics of the seed as a function of the crank angle phi, with the first and
# second derivatives with respect to phi (the branch with the piston outboard of the crank pin).
# ----------------------------------------------------------------------------------------------
def kinematics(phi):
    """Returns {body: (x, y, theta)} and, per body, d/dphi and d^2/dphi^2 of (x, y, theta)."""
    s, c = math.sin(phi), math.cos(phi)
    # Crank pin P(phi) and its derivatives.
    p = (-CRANK_RADIUS * s, CRANK_RADIUS * c)
    dp = (-CRANK_RADIUS * c, -CRANK_RADIUS * s)
    ddp = (CRANK_RADIUS * s, -CRANK_RADIUS * c)
    # Piston pin Q = (P_x + w, 0), w = sqrt(L^2 - P_y^2).
    w = math.sqrt(ROD_LENGTH**2 - p[1] ** 2)
    dw = -p[1] * dp[1] / w
    ddw = (-dp[1] ** 2 - p[1] * ddp[1] - dw**2) / w
    qx, dqx, ddqx = p[0] + w, dp[0] + dw, ddp[0] + ddw
    # Rod angle: Q - P = (w, -P_y) = A(theta_C) (-41.3, 102.6), |Q - P| = L constant.
    offset = math.atan2(ROD_PIN_PISTON[1] - ROD_PIN_CRANK[1], ROD_PIN_PISTON[0] - ROD_PIN_CRANK[0])
    th_c = math.atan2(-p[1], w) - offset
    dth_c = (-w * dp[1] + p[1] * dw) / ROD_LENGTH**2
    ddth_c = (-w * ddp[1] + p[1] * ddw) / ROD_LENGTH**2
    # Rod reference point: r_C = P - A(theta_C) s, s = (41.3, 0) the crank pin on the rod.
    a = rot(th_c, ROD_PIN_CRANK)  # A s
    da = (-a[1], a[0])  # d(A s)/dtheta
    r_c = (p[0] - a[0], p[1] - a[1])
    dr_c = (dp[0] - dth_c * da[0], dp[1] - dth_c * da[1])
    ddr_c = (
        ddp[0] - ddth_c * da[0] + dth_c**2 * a[0],
        ddp[1] - ddth_c * da[1] + dth_c**2 * a[1],
    )
    x_b = qx - PISTON_PIN[0]
    return {
        "piston": ((x_b, 0.0, 0.0), (dqx, 0.0, 0.0), (ddqx, 0.0, 0.0)),
        "rod": ((r_c[0], r_c[1], th_c), (dr_c[0], dr_c[1], dth_c), (ddr_c[0], ddr_c[1], ddth_c)),
        "crank": ((0.0, 0.0, phi), (0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),
    }


def reduced_rhs(_t, y):
    """The reduced Lagrange equation m(phi) phi'' + c(phi) phi'^2 = Q(phi) as a first-order system.

    m = sum m_i |r_i'|^2 + I_i theta_i'^2, c = sum m_i r_i' . r_i'' + I_i theta_i' theta_i''
    (half of dm/dphi), Q = sum m_i g . r_i' (gravity along y).
    """
    phi, rate = y
    k = kinematics(phi)
    m = c = q = 0.0
    for body, (_, d1, d2) in k.items():
        mass, inertia = MASS[body], INERTIA[body]
        m += mass * (d1[0] ** 2 + d1[1] ** 2) + inertia * d1[2] ** 2
        c += mass * (d1[0] * d2[0] + d1[1] * d2[1]) + inertia * d1[2] * d2[2]
        q += mass * GRAVITY * d1[1]
    return [rate, (q - c * rate**2) / m]


def reference(times):
    """Crank angle at `times` from rest at PHI0, integrated to 1e-12 (scipy) or by fine RK4."""
    try:
        from scipy.integrate import solve_ivp
    except ImportError:
        return reference_rk4(times), "classical RK4, h = 1e-6 s (scipy unavailable)"
    solution = solve_ivp(
        reduced_rhs, (0.0, max(times)), [PHI0, 0.0], method="DOP853",
        t_eval=times, rtol=1e-12, atol=1e-12,
    )
    if not solution.success:
        sys.exit(f"reference integration failed: {solution.message}")
    return list(solution.y[0]), "scipy solve_ivp DOP853, rtol = atol = 1e-12"


def reference_rk4(times, h=1e-6):
    y, t, out = [PHI0, 0.0], 0.0, []
    for target in times:
        n = max(1, round((target - t) / h))
        step = (target - t) / n
        for _ in range(n):
            k1 = reduced_rhs(t, y)
            k2 = reduced_rhs(t, [y[i] + 0.5 * step * k1[i] for i in range(2)])
            k3 = reduced_rhs(t, [y[i] + 0.5 * step * k2[i] for i in range(2)])
            k4 = reduced_rhs(t, [y[i] + step * k3[i] for i in range(2)])
            y = [y[i] + step / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(2)]
            t += step
        out.append(y[0])
    return out


# ----------------------------------------------------------------------------------------------
# The seed in Exudyn.
# ----------------------------------------------------------------------------------------------
def build(exu, rho_inf, step):
    """The free seed as an Exudyn system, assembled at PHI0 from rest, with its settings."""
    import exudyn.itemInterface as items

    system = exu.SystemContainer()
    mbs = system.AddSystem()
    pose = {body: k[0] for body, k in kinematics(PHI0).items()}

    def rigid_body(name):
        node = mbs.AddNode(items.NodeRigidBody2D(
            referenceCoordinates=list(pose[name]), initialVelocities=[0.0, 0.0, 0.0]))
        body = mbs.AddObject(items.ObjectRigidBody2D(
            name=name, nodeNumber=node, mass=MASS[name], inertia=INERTIA[name]))
        # Gravity: the mass-proportional load g (Exudyn multiplies by the body's mass).
        mbs.AddLoad(items.LoadMassProportional(
            markerNumber=mbs.AddMarker(items.MarkerBodyMass(bodyNumber=body)),
            loadVector=[0.0, GRAVITY, 0.0]))
        return node, body

    liner = mbs.AddObject(items.ObjectGround(referencePosition=[LINER[0], LINER[1], 0.0]))
    bearing = mbs.AddObject(items.ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
    _, piston = rigid_body("piston")
    _, rod = rigid_body("rod")
    crank_node, crank = rigid_body("crank")

    def point(body, local):
        return mbs.AddMarker(items.MarkerBodyPosition(
            bodyNumber=body, localPosition=[local[0], local[1], 0.0]))

    def rigid(body):
        return mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))

    revolute = items.ObjectJointRevolute2D
    mbs.AddObject(revolute(
        markerNumbers=[point(rod, ROD_PIN_CRANK), point(crank, (0.0, CRANK_RADIUS))]))
    mbs.AddObject(revolute(markerNumbers=[point(piston, PISTON_PIN), point(rod, ROD_PIN_PISTON)]))
    mbs.AddObject(revolute(markerNumbers=[point(crank, (0.0, 0.0)), point(bearing, (0.0, 0.0))]))
    # The piston's reference point on the liner's x axis, no relative rotation.
    mbs.AddObject(items.ObjectJointPrismatic2D(
        markerNumbers=[rigid(liner), rigid(piston)], axisMarker0=[1.0, 0.0, 0.0],
        normalMarker1=[0.0, 1.0, 0.0], constrainRotation=True))

    sensor = mbs.AddSensor(items.SensorNode(
        nodeNumber=crank_node, outputVariableType=exu.OutputVariableType.Rotation,
        storeInternal=True, writeToFile=False))
    mbs.Assemble()

    settings = exu.SimulationSettings()
    ti = settings.timeIntegration
    ti.endTime = T_END
    ti.numberOfSteps = round(T_END / step)
    ti.automaticStepSize = False
    ti.adaptiveStep = False
    ti.generalizedAlpha.spectralRadius = rho_inf
    ti.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = 0.1  # the report times
    settings.show.computationTime = False
    settings.show.statistics = False
    return system, mbs, settings, sensor


def run_exudyn(exu, rho_inf, step):
    """One run: seconds in SolveSteps, its iteration counts, the crank angle at REPORT_TIMES."""
    _system, mbs, settings, sensor = build(exu, rho_inf, step)
    solver = exu.MainSolverImplicitSecondOrder()
    if not solver.InitializeSolver(mbs, settings):
        sys.exit("Exudyn: InitializeSolver failed")
    started = time.perf_counter()
    success = solver.SolveSteps(mbs, settings)
    elapsed = time.perf_counter() - started
    solver.FinalizeSolver(mbs, settings)
    if not success:
        sys.exit(f"Exudyn: SolveSteps failed: {solver.GetErrorString()}")
    data = mbs.GetSensorStoredData(sensor)  # rows (t, angle)
    angles = []
    for target in REPORT_TIMES:
        row = min(data, key=lambda r: abs(r[0] - target))
        if abs(row[0] - target) > 0.5 * step:
            sys.exit(f"Exudyn: no sensor output at t = {target} (nearest {row[0]})")
        angles.append(float(row[-1]))
    counts = (solver.it.numberOfSteps, solver.it.newtonStepsCount, solver.it.newtonJacobiCount)
    return elapsed, counts, angles


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--step", type=float, default=1e-4, help="fixed step (s), default 1e-4")
    parser.add_argument("--rho-inf", type=float, default=0.9,
                        help="generalized-alpha spectral radius at infinity, default 0.9")
    parser.add_argument("--repeats", type=int, default=7, help="timed runs, default 7")
    parser.add_argument("--reference-only", action="store_true",
                        help="print the reference only (no Exudyn)")
    parser.add_argument("--summary", action="store_true",
                        help="print one line `exudyn key=value ...` only (for the Rust benchmark)")
    args = parser.parse_args()

    ref, how = reference(REPORT_TIMES)
    if not args.summary:
        print(f"reference: reduced Lagrange equation of the free seed, {how}")
    if args.reference_only:
        for t, phi in zip(REPORT_TIMES, ref):
            print(f"  t = {t:.1f} s   phi = {phi:.12f} rad")
        return

    try:
        import exudyn as exu
    except ImportError as error:
        sys.exit(f"exudyn is not installed ({error}); `pip install exudyn`, or --reference-only")

    runs = [run_exudyn(exu, args.rho_inf, args.step) for _ in range(args.repeats)]
    per_step = [elapsed / counts[0] for elapsed, counts, _ in runs]
    steps, newton, jacobians = runs[0][1]
    angles = runs[0][2]
    if any(r[2] != angles for r in runs):
        print("warning: repeated runs disagree on the crank angle", file=sys.stderr)
    worst = max(abs(a - b) for a, b in zip(angles, ref))
    if args.summary:
        print(f"exudyn version={exu.__version__} step={args.step:g} rho_inf={args.rho_inf} "
              f"us_per_step_median={statistics.median(per_step) * 1e6:.3f} "
              f"us_per_step_fastest={min(per_step) * 1e6:.3f} max_abs_dphi={worst:.3e}")
        return
    print(f"Exudyn {exu.__version__}, Python {sys.version.split()[0]}: generalized-alpha "
          f"(index 3), rho_inf = {args.rho_inf}, fixed step h = {args.step:g} s, "
          f"{steps} steps to {T_END} s ({newton / steps:.2f} Newton iterations per step, "
          f"{jacobians} Jacobian factorizations), {args.repeats} runs")
    print(f"  {'t (s)':>6} {'Exudyn phi (rad)':>18} {'reference (rad)':>18} {'|dphi| (rad)':>12}")
    for t, phi, phi_ref in zip(REPORT_TIMES, angles, ref):
        print(f"  {t:>6.1f} {phi:>18.12f} {phi_ref:>18.12f} {abs(phi - phi_ref):>12.3e}")
    print()
    print(f"  {'peer':<10} {'us/step (median)':>17} {'us/step (fastest)':>18} "
          f"{'max |dphi| (rad)':>17}")
    print(f"  {'Exudyn':<10} {statistics.median(per_step) * 1e6:>17.2f} "
          f"{min(per_step) * 1e6:>18.2f} {worst:>17.3e}")


if __name__ == "__main__":
    main()
