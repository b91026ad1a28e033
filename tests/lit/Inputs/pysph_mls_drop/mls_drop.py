"""PySPH 1.0b1 side of tests/lit/ported/pysph-mls-drop.sph: PySPH's own example
elliptical_drop_no_scheme.py (its particles, TaitEOS, ContinuityEquation, MomentumEquation,
XSPHCorrection, EPECIntegrator with WCSPHStep) with one more group in front: PySPH's
MLSFirstOrder2D density re-initialisation (pysph.sph.wc.density_correction: a loop_all over
the neighbour list that solves a 3x3 moving-least-squares system through its helper
functions gj_solve/augmented_matrix), run only while a run-time condition on t holds.

The condition is a window t_on < t < t_off with t_on = 100.25 dt and t_off = 300.25 dt: the
EPEC integrator evaluates the accelerations at t_n and at t_n + dt/2 (do_post_stage(0.5*dt)),
so the first filtered evaluation is the second one of step 100 and the last the first one of
step 300 (a code that passed t_n to both evaluations would start half a step later).

Fixed dt = 5e-6 (no adaptive step, no start-up damping), nx = 10 (317 particles), tf = 0.002
(400 steps), a snapshot every 40 steps.

  /usr/bin/python3 mls_drop.py -d OUT      (make_reference.sh passes the options)
"""
from pysph.examples.elliptical_drop_no_scheme import EllipticalDrop
from pysph.sph.equation import Group
from pysph.sph.wc.density_correction import MLSFirstOrder2D

DT = 5e-6
T_ON = 100.25 * DT
T_OFF = 300.25 * DT


def filter_window(t, dt):
    return T_ON < t < T_OFF


class MLSDrop(EllipticalDrop):
    def create_particles(self):
        [pa] = EllipticalDrop.create_particles(self)
        pa.add_property('rhotmp')
        return [pa]

    def create_solver(self):
        solver = EllipticalDrop.create_solver(self)
        solver.set_final_time(0.002)
        return solver

    def create_equations(self):
        equations = EllipticalDrop.create_equations(self)
        mls = Group(equations=[MLSFirstOrder2D(dest='fluid', sources=['fluid'])],
                    condition=filter_window)
        return [mls] + equations


if __name__ == '__main__':
    app = MLSDrop()
    app.run()
