"""The resistance of two spheres of radii a1 and a2 built from their scalar functions, as
src/kernels/resistance_blocks.F90 builds it (doc/METHOD.md §5.1, §5.7; doc/LUBRICATION.md "Tables
for mixtures"): the forces, torques and stresslets of both spheres for given velocities and an
imposed strain. scripts/calibrate.py fits the resolved scalars of an unequal pair to what fdsusp
measures with it; the model being linear in the scalars, the fit is a linear least-squares problem
whose columns are responses to one scalar at a time.

Scalars: s[k, alpha, beta], k in the order of NAMES11 (X^A, Y^A, Y^B, X^C, Y^C, X^G, Y^G, Y^H,
X^M, Y^M, Z^M), for each block (alpha, beta) in the frame where d points from sphere 1 to sphere
2, scaled as Jeffrey & Onishi (1984) scale them: A by 3 pi eta (a_alpha + a_beta), B and G by
pi eta (a_alpha + a_beta)^2, C and H by pi eta (a_alpha + a_beta)^3, M by (5/6) pi eta
(a_alpha + a_beta)^3. In the arrays f (sphere 1: the 11 then the 12 scalars) and f2 (sphere 2:
22 then 21) of mod_lubrication, s[:, 0, 0] = f[:11], s[:, 0, 1] = f[11:], s[:, 1, 1] = f2[:11],
s[:, 1, 0] = f2[11:].
"""
import numpy as np

NAMES11 = ["XA", "YA", "YB", "XC", "YC", "XG", "YG", "YH", "XM", "YM", "ZM"]
K = {n: i for i, n in enumerate(NAMES11)}
EPS = np.zeros((3, 3, 3))
EPS[0, 1, 2] = EPS[1, 2, 0] = EPS[2, 0, 1] = 1.0
EPS[0, 2, 1] = EPS[2, 1, 0] = EPS[1, 0, 2] = -1.0
I3 = np.eye(3)


def radius_sums(a1, a2):
    return np.array([[2 * a1, a1 + a2], [a1 + a2, 2 * a2]])


def g_tensor(xg, yg, d):
    """G_ijk = XG (d_i d_j - delta_ij/3) d_k + YG (d_i delta_jk + d_j delta_ik - 2 d_i d_j d_k)."""
    dd = np.outer(d, d)
    return (xg * np.einsum('ij,k->ijk', dd - I3 / 3, d)
            + yg * (np.einsum('i,jk->ijk', d, I3) + np.einsum('j,ik->ijk', d, I3) - 2 * np.einsum('ij,k->ijk', dd, d)))


def h_tensor(yh, d):
    """H_ijk = YH (eps_ikl d_l d_j + eps_jkl d_l d_i)."""
    e = np.einsum('ikl,l->ik', EPS, d)
    return yh * (np.einsum('ik,j->ijk', e, d) + np.einsum('jk,i->ijk', e, d))


def m_tensor(xm, ym, zm, d):
    """M = XM d0 + YM d1 + ZM d2 (Kim & Karrila 11.2)."""
    dd = np.outer(d, d)
    dddd = np.einsum('ij,kl->ijkl', dd, dd)
    d0 = 1.5 * np.einsum('ij,kl->ijkl', dd - I3 / 3, dd - I3 / 3)
    cross = (np.einsum('i,jl,k->ijkl', d, I3, d) + np.einsum('j,il,k->ijkl', d, I3, d)
             + np.einsum('i,jk,l->ijkl', d, I3, d) + np.einsum('j,ik,l->ijkl', d, I3, d))
    d1 = 0.5 * (cross - 4 * dddd)
    d2 = 0.5 * (np.einsum('ik,jl->ijkl', I3, I3) + np.einsum('jk,il->ijkl', I3, I3) - np.einsum('ij,kl->ijkl', I3, I3)
                + np.einsum('ij,kl->ijkl', dd, I3) + np.einsum('ij,kl->ijkl', I3, dd) + dddd - cross)
    return xm * d0 + ym * d1 + zm * d2


def responses(s, a1, a2, d, w, e, viscosity=1.0):
    """Forces, torques and stresslets (F (2, 3), T (2, 3), S (2, 3, 3)) of the pair for
    w (2, 6) = (U_inf - U, Omega_inf - Omega) of each sphere and the strain rate e (3, 3):
    (F, T)_alpha = R_FU . w + R_FE : E and S_alpha = R_SU . w + R_SE : E, the blocks of
    resistance_blocks.F90 (pair_resistance_fu_sized, _fe_sized, _su_sized, _se_sized)."""
    sa = radius_sums(a1, a2)
    F = np.zeros((2, 3))
    T = np.zeros((2, 3))
    S = np.zeros((2, 3, 3))
    b = np.einsum('ijk,k->ij', EPS, d)          # b_ij = eps_ijk d_k
    dd = np.outer(d, d)
    for al in range(2):
        for be in range(2):
            ca, cb, cc = 3 * np.pi * viscosity * sa[al, be], np.pi * viscosity * sa[al, be] ** 2, \
                np.pi * viscosity * sa[al, be] ** 3
            x = s[:, al, be]
            u, o = w[be, :3], w[be, 3:]
            F[al] += ca * (x[K['XA']] * dd + x[K['YA']] * (I3 - dd)) @ u
            T[al] += cc * (x[K['XC']] * dd + x[K['YC']] * (I3 - dd)) @ o
            # T_alpha <- U_beta: B^ab_ij = YB^ab eps_ijk d_k
            T[al] += cb * x[K['YB']] * b @ u
            # F_beta <- Omega_alpha: the transpose of that block
            F[be] += cb * x[K['YB']] * b.T @ w[al, 3:]
            # S_alpha <- w_beta (G and H of block (alpha, beta))
            S[al] += cb * np.einsum('ijk,k->ij', g_tensor(x[K['XG']], x[K['YG']], d), u)
            S[al] += cc * np.einsum('ijk,k->ij', h_tensor(x[K['YH']], d), o)
            # F_alpha <- E: the transpose of the stresslet blocks (beta, alpha)
            y = s[:, be, al]
            F[al] += cb * np.einsum('jki,jk->i', g_tensor(y[K['XG']], y[K['YG']], d), e)
            T[al] += cc * np.einsum('jki,jk->i', h_tensor(y[K['YH']], d), e)
        cm = 5.0 / 6.0 * np.pi * viscosity * sa[al] ** 3
        m = [np.dot(s[K[n], al, :], cm) for n in ('XM', 'YM', 'ZM')]
        S[al] += np.einsum('ijkl,kl->ij', m_tensor(*m, d), e)
    return F, T, S


def fold_strain(s, a1, a2):
    """The M scalars of each sphere folded into its self slot (11, 22) and the cross slots (12, 21)
    zeroed: the strain stresslet of sphere alpha in units of (20/3) pi eta a_alpha^3, which is all
    R_SE needs (doc/LUBRICATION.md "Tables for mixtures")."""
    s = np.array(s, dtype=float)
    a = (a1, a2)
    for al in range(2):
        be = 1 - al
        ratio = ((a1 + a2) / (2 * a[al])) ** 3
        for n in ('XM', 'YM', 'ZM'):
            s[K[n], al, al] += ratio * s[K[n], al, be]
            s[K[n], al, be] = 0.0
    return s


EXCHANGE = np.array([1, 1, -1, 1, 1, -1, -1, 1, 1, 1, 1] * 2, dtype=float)


def exact_scalars(gap, size_ratio):
    """s[k, alpha, beta] of radii 1 and size_ratio from bin/fdsusp-resistance: sphere 1's at
    size_ratio, sphere 2's from 1/size_ratio with the exchange signs (mod_pair_resistance_unequal)."""
    from .resistance import sized_pair
    return from_arrays(sized_pair(gap, size_ratio), EXCHANGE * sized_pair(gap, 1.0 / size_ratio))


def exact_pair_part(gap, size_ratio):
    """R_2B - R_1B of radii 1 and size_ratio, M folded: what a table of an unequal pair holds for a
    grid that resolved everything (each sphere's one-body self scalars X^A, Y^A, X^C, Y^C, X^M,
    Y^M, Z^M are 1 in Jeffrey & Onishi's scaling)."""
    s = exact_scalars(gap, size_ratio)
    for n in ('XA', 'YA', 'XC', 'YC', 'XM', 'YM', 'ZM'):
        for al in range(2):
            s[K[n], al, al] -= 1.0
    return fold_strain(s, 1.0, size_ratio)


def from_arrays(f, f2):
    """s[k, alpha, beta] from mod_lubrication's f (11, 12 scalars) and f2 (22, 21 scalars)."""
    s = np.zeros((11, 2, 2))
    s[:, 0, 0], s[:, 0, 1], s[:, 1, 1], s[:, 1, 0] = f[:11], f[11:], f2[:11], f2[11:]
    return s


def to_arrays(s):
    """mod_lubrication's f and f2 from s[k, alpha, beta]."""
    return np.concatenate([s[:, 0, 0], s[:, 0, 1]]), np.concatenate([s[:, 1, 1], s[:, 1, 0]])


def balanced(s, a1, a2, d, u, o):
    """The velocities u (2, 3) plus the co-moving translation that makes the net force of the
    pair vanish for the resistance s (the exact one) with spins o (2, 3) in a fluid at rest.
    Unequal spheres in relative motion, or a sphere spinning beside another, exert a net force,
    and a periodic box under a net force has no steady state (its fluid accelerates); the
    co-moving translation is a regular motion, which the grid resolves."""
    u, o = np.array(u, dtype=float), np.array(o, dtype=float)

    def net_force(uu):
        F, _, _ = responses(s, a1, a2, d, np.hstack([-uu, -o]), np.zeros((3, 3)))
        return F[0] + F[1]

    base = net_force(u)
    per_unit = np.array([net_force(u + np.outer([1, 1], v)) - base for v in np.eye(3)]).T
    return u + np.outer([1, 1], np.linalg.solve(per_unit, -base))
