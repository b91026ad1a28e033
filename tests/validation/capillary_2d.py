#!/usr/bin/env python3
"""The linear capillary oscillation of a 2D drop (a circular cylinder of radius R) in another
fluid, both viscous: the complex frequency s = -gamma + i omega of the mode n, from the exact
normal-mode analysis of the linearised (unsteady Stokes) equations, and its small-viscosity
limit. Used by square_droplet.py --oscillation; run alone it prints a table.

The normal-mode analysis is that of Prosperetti (J. Mecanique 19 (1980) 149-182, for a
sphere; Miller & Scriven, J. Fluid Mech. 32 (1968) 417-435, likewise) written for a circular
interface in the plane, which is the case of a 2D SPH drop. With time dependence e^{st} the
velocity of each fluid is u = grad phi + curl(psi z^), phi harmonic, (lap - s/nu) psi = 0, and
the pressure p = -rho s phi:

    inside:  phi = A r^n cos n th,    psi = C I_n(q r) sin n th,
    outside: phi = B r^-n cos n th,   psi = D K_n(q r) sin n th,     q = sqrt(s / nu),

(I_n, K_n the modified Bessel functions). At r = R, with the interface r = R + a cos n th:
the velocity continuous (u_r, u_th), the shear stress continuous, the kinematic condition
s a = u_r, and the normal stress jumps by sigma times the curvature's perturbation
(n^2 - 1) a / R^2 (Young-Laplace). The four homogeneous equations in A, B, C, D have a
solution where their determinant vanishes: that is s. Equal densities and viscosities on both
sides (the SPH test: one fluid, two colours).

Limits (both checked by `python3 capillary_2d.py`): nu -> 0 gives Rayleigh's frequency for
two fluids (Lamb, Hydrodynamics, art. 275), omega0^2 = (n^3 - n) sigma / (2 rho R^3).
For small nu, the tangential velocities of the two potential flows are opposite at the
interface (u_th jumps by 2 n A R^{n-1}), so a vortical boundary layer of thickness
sqrt(2 nu / omega0) forms there, and its dissipation dominates: Lamb's dissipation method
(Hydrodynamics, arts. 348-351) with a Stokes layer on each side gives the leading terms

    gamma ~ n sqrt(nu omega0) / (2 sqrt(2) R),    omega ~ omega0 - n sqrt(nu omega0) / (2 sqrt(2) R)

(the layer shifts the frequency by as much as it damps, as Stokes layers do). The exact root
below agrees with both to 1% at nu = 1e-6 and with omega to 0.02% up to nu = 0.01; gamma's
next term, O(nu), is not the potential flows' own dissipation (2 n^2 nu / R^2, 8 times too
large here), and at the SPH test's nu (the layer 0.15 R thick at nu = 0.01) the leading term
is 13% below the exact gamma (27% at nu = 0.05): the check uses the exact root.

Needs only numpy: I_n and K_n of a complex argument by their integral representations
(trapezoidal rule: I_n's integrand is periodic, K_n's decays doubly exponentially).
"""
import sys

import numpy as np

_TH = np.linspace(0.0, np.pi, 2049)
_T = np.linspace(0.0, 12.0, 6001)


def _trap(f, x):
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)).real) + 1j * float(
        np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)).imag)


def bessel_i(n, z):
    """I_n(z) = (1/pi) int_0^pi exp(z cos t) cos(n t) dt (integer n)."""
    return _trap(np.exp(z * np.cos(_TH)) * np.cos(n * _TH), _TH) / np.pi


def bessel_k(n, z):
    """K_n(z) = int_0^inf exp(-z cosh t) cosh(n t) dt (Re z > 0)."""
    return _trap(np.exp(-z * np.cosh(_T)) * np.cosh(n * _T), _T)


def _bessel_derivs(n, z, kind):
    """(F, F', F'') of F = I_n or K_n at z (recurrences and Bessel's equation)."""
    if kind == "i":
        f, fm = bessel_i(n, z), bessel_i(n - 1, z)
        d1 = fm - n / z * f
    else:
        f, fm = bessel_k(n, z), bessel_k(n - 1, z)
        d1 = -fm - n / z * f
    d2 = (1.0 + n * n / (z * z)) * f - d1 / z
    return f, d1, d2


def lattice_sum(n, terms=400):
    """G_2n = sum over the square lattice's points w = m + i k other than 0 of w^-2n (the
    images of a drop in a periodic box of side 1; G_4 = Gamma(1/4)^8 / (960 pi^2) = 3.1512).
    Zero for odd n (by the lattice's symmetry)."""
    if n % 2:
        return 0.0
    m = np.arange(-terms, terms + 1, dtype=float)
    w = m[:, None] + 1j * m[None, :]
    w[terms, terms] = 1.0
    t = w ** (-2 * n)
    t[terms, terms] = 0.0
    return float(t.sum().real)


def image_coefficient(n, box):
    """eps' of the outer potential B (r^-n + eps' r^n) cos n th in a periodic square box of
    side `box` (None: no box): the n-pole's periodic images, expanded about the drop's centre,
    add the regular part binom(2n - 1, n) G_2n r^n / box^2n (for n = 2: 3 G_4 r^2 / box^4)."""
    if box is None:
        return 0.0
    from math import comb
    return comb(2 * n - 1, n) * lattice_sum(n) / box ** (2 * n)


def _vortical(s, n, R, nu):
    """The vortical solutions' wave number q (Re q >= 0) for the complex frequency s, z = q R,
    and (F, F', F'') at z of I_n and K_n."""
    q = np.sqrt(s / nu + 0j)
    if q.real < 0:
        q = -q
    z = q * R
    return q, z, _bessel_derivs(n, z, "i"), _bessel_derivs(n, z, "k")


def determinant(s, n, R, sigma, rho, nu, box=None):
    """The determinant of the interface conditions for the complex frequency s."""
    mu = rho * nu
    q, z, (fi, di, ddi), (fk, dk, ddk) = _vortical(s, n, R, nu)
    r = R
    e = image_coefficient(n, box)
    # Per unknown (A, B, C, D): U_r, U_r', U_th, U_th', Phi at r = R (the cos / sin
    # coefficients of u_r, u_th and phi); inside A, C, outside B, D.
    cols = {
        "A": (n * r ** (n - 1), n * (n - 1) * r ** (n - 2), -n * r ** (n - 1),
              -n * (n - 1) * r ** (n - 2), r ** n),
        "C": (n * fi / r, n * (q * di / r - fi / r ** 2), -q * di, -q * q * ddi, 0.0),
        "B": (-n * r ** (-n - 1) + e * n * r ** (n - 1),
              n * (n + 1) * r ** (-n - 2) + e * n * (n - 1) * r ** (n - 2),
              -n * r ** (-n - 1) - e * n * r ** (n - 1),
              n * (n + 1) * r ** (-n - 2) - e * n * (n - 1) * r ** (n - 2),
              r ** (-n) + e * r ** n),
        "D": (n * fk / r, n * (q * dk / r - fk / r ** 2), -q * dk, -q * q * ddk, 0.0),
    }
    M = np.zeros((4, 4), complex)
    for j, key in enumerate("ACBD"):
        ur, urp, ut, utp, phi = cols[key]
        sign = 1.0 if key in "AC" else -1.0           # inside minus outside
        shear = mu * (utp - ut / r - n * ur / r)
        normal = rho * s * phi + 2 * mu * urp
        M[0, j] = sign * ur
        M[1, j] = sign * ut
        M[2, j] = sign * shear
        M[3, j] = sign * normal
        if key in "AC":                                # + sigma (n^2 - 1) a / R^2, s a = u_r(in)
            M[3, j] += sigma * (n * n - 1) / R ** 2 * ur / s
    return np.linalg.det(M)


def _amplitude_transform(s, n, R, sigma, rho, nu, box=None):
    """The Laplace transform a^(s) of the interface's amplitude a(t) / a(0) for the drop
    started from rest (u = 0) with the shape R + a(0) cos n th: the interface conditions of
    determinant() with the transformed unknowns, whose kinematic condition is now
    s a^ - a(0) = u_r^(R); the initial amplitude moves to the right-hand side of the normal
    stress row. The vortical columns are divided by I_n(qR) and K_n(qR) (the same solution,
    better conditioned for large |qR|)."""
    mu = rho * nu
    q, z, (fi, di, ddi), (fk, dk, ddk) = _vortical(s, n, R, nu)
    di, ddi, dk, ddk = di / fi, ddi / fi, dk / fk, ddk / fk
    r = R
    e = image_coefficient(n, box)
    cols = (
        (n * r ** (n - 1), n * (n - 1) * r ** (n - 2), -n * r ** (n - 1),
         -n * (n - 1) * r ** (n - 2), r ** n, 1.0),
        (n / r, n * (q * di / r - 1 / r ** 2), -q * di, -q * q * ddi, 0.0, 1.0),
        (-n * r ** (-n - 1) + e * n * r ** (n - 1),
         n * (n + 1) * r ** (-n - 2) + e * n * (n - 1) * r ** (n - 2),
         -n * r ** (-n - 1) - e * n * r ** (n - 1),
         n * (n + 1) * r ** (-n - 2) - e * n * (n - 1) * r ** (n - 2),
         r ** (-n) + e * r ** n, -1.0),
        (n / r, n * (q * dk / r - 1 / r ** 2), -q * dk, -q * q * ddk, 0.0, -1.0),
    )
    M = np.zeros((4, 4), complex)
    urin = np.zeros(4, complex)
    for j, (ur, urp, ut, utp, phi, sign) in enumerate(cols):
        M[0, j] = sign * ur
        M[1, j] = sign * ut
        M[2, j] = sign * mu * (utp - ut / r - n * ur / r)
        M[3, j] = sign * (rho * s * phi + 2 * mu * urp)
        if sign > 0:
            M[3, j] += sigma * (n * n - 1) / R ** 2 * ur / s
            urin[j] = ur
    rhs = np.zeros(4, complex)
    rhs[3] = -sigma * (n * n - 1) / R ** 2 / s
    return (1.0 + urin @ np.linalg.solve(M, rhs)) / s


def initial_value(n, R, sigma, rho, nu, box, times, terms=48):
    """a(t) / a(0) at the times t > 0 (t = 0: 1) for the drop started from rest, the
    initial-value problem of Prosperetti (J. Fluid Mech. 100 (1980) 333-347, for a sphere)
    written for the circle: the inverse Laplace transform of _amplitude_transform by the fixed
    Talbot contour (Abate & Valko, Int. J. Numer. Meth. Engng 60 (2004) 979-993) with `terms`
    nodes. Unlike the normal mode, its damping starts lower (the vorticity layer at the
    interface has to diffuse out first): fitted over the same window as the SPH run, it is the
    reference the damping rate is compared with. The contour must pass to the right of the
    mode's poles (r = 2 terms / (5 t) large enough): at nu = 0.005-0.01, 40, 48 and 56 nodes
    agree to 1e-6 up to t = 2 (32 nodes do not at t = 2: the pole falls outside)."""
    out = []
    for t in times:
        if t <= 0:
            out.append(1.0)
            continue
        r = 2.0 * terms / (5.0 * t)
        total = 0.5 * (_amplitude_transform(complex(r), n, R, sigma, rho, nu, box)
                       * np.exp(r * t)).real
        for k in range(1, terms):
            th = k * np.pi / terms
            cot = 1.0 / np.tan(th)
            s = r * th * (cot + 1j)
            dsig = th + (th * cot - 1.0) * cot
            total += (np.exp(t * s) * _amplitude_transform(s, n, R, sigma, rho, nu, box)
                      * (1.0 + 1j * dsig)).real
        out.append(r / terms * total)
    return np.array(out)


def omega0(n, R, sigma, rho, box=None):
    """Rayleigh's frequency of two inviscid fluids of equal density rho; in a periodic box,
    times sqrt(1 - eps' R^2n) (the images' potential adds to the outer fluid's inertia)."""
    return np.sqrt((n ** 3 - n) * sigma / (2 * rho * R ** 3)
                   * (1 - image_coefficient(n, box) * R ** (2 * n)))


def asymptotic(n, R, sigma, rho, nu, box=None):
    """(omega, gamma) of the small-viscosity limit above (leading terms)."""
    w0 = omega0(n, R, sigma, rho, box)
    layer = n * np.sqrt(nu * w0) / (2 * np.sqrt(2) * R)
    return w0 - layer, layer


def mode(n, R, sigma, rho, nu, box=None):
    """(omega, gamma) of the least-damped oscillating mode n: the root of the determinant
    (secant iterations from the small-viscosity limit); box: the side of a periodic box."""
    w, g = asymptotic(n, R, sigma, rho, nu, box)
    s0 = complex(-g, w)
    s1 = s0 * (1 + 1e-3)
    f0 = determinant(s0, n, R, sigma, rho, nu, box)
    f1 = determinant(s1, n, R, sigma, rho, nu, box)
    for _ in range(60):
        s2 = s1 - f1 * (s1 - s0) / (f1 - f0)
        if abs(s2 - s1) < 1e-12 * abs(s2):
            s1 = s2
            break
        s0, f0 = s1, f1
        s1, f1 = s2, determinant(s2, n, R, sigma, rho, nu, box)
    else:
        raise RuntimeError("capillary_2d: no root for nu = %g" % nu)
    return s1.imag, -s1.real


def main():
    R = 0.5 / np.sqrt(np.pi)
    sigma = rho = 1.0
    n = 2
    w0 = omega0(n, R, sigma, rho)
    print("n = 2, R = %.4f, sigma = rho = 1: Rayleigh (two fluids) omega0 = %.4f" % (R, w0))
    print("G_4 = %.5f (Gamma(1/4)^8 / (960 pi^2) = 3.15121); in the periodic box of side 1:"
          " omega0 = %.4f" % (lattice_sum(2), omega0(n, R, sigma, rho, 1.0)))
    print("%8s %10s %10s %10s %10s %12s %10s %10s" % (
        "nu", "omega", "gamma", "omega asym", "gamma asym", "omega/omega0", "box omega",
        "box gamma"))
    for nu in (1e-6, 1e-5, 1e-4, 1e-3, 0.002, 0.005, 0.01, 0.02, 0.05):
        w, g = mode(n, R, sigma, rho, nu)
        wa, ga = asymptotic(n, R, sigma, rho, nu)
        wb, gb = mode(n, R, sigma, rho, nu, 1.0)
        print("%8g %10.4f %10.4f %10.4f %10.4f %12.4f %10.4f %10.4f"
              % (nu, w, g, wa, ga, w / w0, wb, gb))
    return 0


if __name__ == "__main__":
    sys.exit(main())
