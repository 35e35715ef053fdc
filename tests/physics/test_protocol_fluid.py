"""Invariant: a pure fluid between walls follows an oscillating imposed shear (doc/INPUT.md
"&shear"; issue 46). DNS without particles, 4a cube at a/Delta = 2 (8 cells across, Delta = 0.5),
gamma(t) = sin(t) (gamma_0 = 1, T = 2 pi: reference rate 1), dt = 0.01, backward Euler
(viscous_theta = 1), 700 steps, initial_flow = 'shear' (the profile of gamma_dot(0)):
1. the imposed rate is gamma_0 omega cos(omega t_n) at every record, and shear/strain is
   gamma_0 sin(omega t_n) (to 1e-13: the same formula evaluated); the walls move with it (the
   wall stresses below measure what the fluid saw);
2. the fluid's shear rate is the imposed one up to the fluid's own relaxation: at Re > 0 the
   profile lags the walls. For a rate slow on the viscous time Re Ly^2 the quasi-steady solution
   of Re du/dt = d2u/dy2 is u = gamma_dot (y - Ly/2) + Re gamma_dot' ((y - Ly/2)^3/6 - Ly^2 (y - Ly/2)/24):
   the wall stress exceeds the rate by Re Ly^2 gamma_dot'/12 and the slope at the centre falls
   short of it by Re Ly^2 gamma_dot'/24 (gamma_dot' from the recorded rates, (rate_n - rate_n-1)/dt).
   Checked at every record for both walls (tau_wall_bottom, tau_wall_top: equal, by symmetry,
   to 1e-12), within 2 (Delta/Ly)^2 of the largest correction (the MAC grid's one-sided wall
   gradient of the cubic: measured 1/64 = (Delta/Ly)^2), and at the centre of the last velocity
   field within 4 (Delta/Ly)^2 (the central difference of a cubic, the wall closure; measured 3 %);
3. the lag is the fluid's, not the method's: at Re 1e-6 the wall stress is the rate within 1/100
   of the deviation at Re 1e-4 (it scales with Re; round-off as Re -> 0).
4. the same fluid in a Lees-Edwards box (doc/METHOD.md §2.4), Re 1e-4: the quasi-steady disturbance
   u - gamma_dot (y - Ly/2) must now be periodic in y with a periodic slope, and the cubic above
   is (its values and slopes at y = 0 and Ly agree), so the mean stress across the sliding
   boundary (tau_wall_bottom there) exceeds the rate by the same Re Ly^2 gamma_dot'/12, checked
   within 2 (Delta/Ly)^2 of the largest correction (the centred difference across the boundary of
   the cubic; measured 1/64 of it, as at the walls); and the offset is gamma(t_{n+1}) Ly mod Lx at
   every record (to 1e-13 a).
Under a second on one core."""
import glob
import math
import os
import h5py
import numpy as np
import fdsusp_testlib as T

L, H, DT = 4.0, 0.5, 0.01
DECK = """&domain box = 4.0, 4.0, 4.0, cells_per_radius = 2 /
&shear protocol = 'oscillatory', strain_amplitude = 1.0, period = 6.283185307179586 /
&fluid reynolds = {re}, viscous_theta = 1.0, initial_flow = 'shear' /
&time dt = 1.0e-2, steps = 700 /
&output directory = 'out', progress_every = 1000 /
"""
deviation = {}
for re in (1.0e-4, 1.0e-6):
    d = T.scratch('protocol_fluid_%g' % re)
    T.run(T.write_deck(d, 'fluid.nml', DECK.format(re=re)), d)
    s = T.series(os.path.join(d, 'out'))
    t_n = s['time'] - DT
    rate = s['shear/rate']
    if re == 1.0e-4:
        err = max(np.max(np.abs(rate - np.cos(t_n))), np.max(np.abs(s['shear/strain'] - np.sin(t_n))))
        T.check(err < 1e-13, 'the imposed rate is cos(t_n), the strain sin(t_n) at every record (%.1e)' % err)
        T.check(np.max(np.abs(s['tau_wall_top'] - s['tau_wall_bottom'])) <= 1e-12,
                'both walls feel the same stress (the fluid is antisymmetric about the centre)')
    slope = np.diff(rate) / DT
    wall = s['tau_wall_bottom'][1:] - rate[1:]
    predicted = re * L ** 2 * slope / 12
    deviation[re] = np.max(np.abs(wall))
    if re == 1.0e-4:
        miss = np.max(np.abs(wall - predicted))
        T.check(miss <= 2 * (H / L) ** 2 * np.max(np.abs(predicted)),
                'Re %g: wall stress - rate = Re Ly^2 gamma_dot\'/12 (largest %.3e) within %.1e <= 2 (Delta/Ly)^2 of it'
                % (re, np.max(np.abs(predicted)), miss))
        # the centre of the last field: u^n after the step from t_n = 6.99 (cell centres; x-z mean)
        path = sorted(glob.glob(os.path.join(d, 'out', 'fields_*.h5')))[-1]
        with h5py.File(path, 'r') as f:
            profile = np.array(f['u']).mean(axis=(0, 2))
        n = len(profile)
        centre = (profile[n // 2] - profile[n // 2 - 1]) / H
        expected = rate[-1] - re * L ** 2 * slope[-1] / 24
        lag = re * L ** 2 * abs(slope[-1]) / 24
        T.check(abs(centre - expected) <= 4 * (H / L) ** 2 * lag,
                'Re %g: slope at the centre %.8f = rate %.8f - Re Ly^2 gamma_dot\'/24 (%.2e) within %.1e'
                % (re, centre, rate[-1], lag, abs(centre - expected)))
# 4. Lees-Edwards
d = T.scratch('protocol_fluid_le')
T.run(T.write_deck(d, 'fluid.nml', DECK.format(re=1.0e-4).replace('cells_per_radius = 2',
                                                                   "cells_per_radius = 2, y_boundary = 'lees-edwards'")), d)
s = T.series(os.path.join(d, 'out'))
rate = s['shear/rate']
predicted = 1.0e-4 * L ** 2 * np.diff(rate) / DT / 12
miss = np.max(np.abs(s['tau_wall_bottom'][1:] - rate[1:] - predicted))
T.check(miss <= 2 * (H / L) ** 2 * np.max(np.abs(predicted)),
        'Lees-Edwards, Re 1e-4: stress across the boundary - rate = Re Ly^2 gamma_dot\'/12 (largest %.3e) within %.1e'
        % (np.max(np.abs(predicted)), miss))
miss = np.max(np.abs(s['lees_edwards_offset'] - np.mod(np.sin(s['time']) * L, L)))
T.check(miss <= 1e-13, 'Lees-Edwards: the offset is gamma(t) Ly mod Lx at every record (%.1e)' % miss)
T.check(deviation[1.0e-6] <= deviation[1.0e-4] / 100 * 1.05,
        'the lag scales with Re: largest |tau_wall - rate| %.2e at Re 1e-6, %.2e at Re 1e-4'
        % (deviation[1.0e-6], deviation[1.0e-4]))
T.finish()
