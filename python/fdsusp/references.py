"""The published fits the paper (Gallier et al. 2014 §4.2-4.8) compares its rheology with, with the
constants as published; each takes numbers or numpy arrays.

    from fdsusp import references
    references.zarraga_eta(0.4)        # relative viscosity, Zarraga, Hill & Leighton 2000
"""
import numpy as np


# Published fits the paper compares with (Gallier et al. 2014 §4.2-4.8), the constants as published:
# Zarraga, Hill & Leighton 2000 (J. Rheol. 44, 185): eta_r = exp(-2.34 phi) / (1 - phi/0.62)^3.
# Dai, Bertevas, Qi & Tanner 2013 (J. Rheol. 57, 493), 0.1 <= phi <= 0.45: N1/tau = -0.8 phi^3,
#   N2/tau = -4.4 phi^3.
# Morris & Boulay 1999 (J. Rheol. 43, 1213): eta_n = K_n (phi/phi_m)^2 / (1 - phi/phi_m)^2,
#   K_n = 0.75, phi_m = 0.68; the paper's fit of that form to its mu_d = 0.5 runs: 1.13, 0.58 (§4.7).
# Boyer, Guazzelli & Pouliquen 2011 (PRL 107, 188301): mu(I_v) = mu_1 + (mu_2 - mu_1)/(1 + I_0/I_v)
#   + I_v + 5/2 phi_m I_v^(1/2), phi(I_v) = phi_m / (1 + I_v^(1/2)); mu_1 = 0.32, mu_2 = 0.7,
#   I_0 = 0.005, phi_m = 0.585. The paper's eta_inf: Krieger-Dougherty, [eta] = 2.4, phi_m' = 0.68.
def zarraga_eta(phi):
    return np.exp(-2.34 * phi) / (1 - phi / 0.62) ** 3


def dai_normal(phi):
    return -0.8 * phi ** 3, -4.4 * phi ** 3


def morris_boulay_eta_n(phi, k_n=0.75, phi_m=0.68):
    return k_n * (phi / phi_m) ** 2 / (1 - phi / phi_m) ** 2


def boyer_mu(i_v, mu_1=0.32, mu_2=0.7, i_0=0.005, phi_m=0.585):
    return mu_1 + (mu_2 - mu_1) / (1 + i_0 / i_v) + i_v + 2.5 * phi_m * np.sqrt(i_v)


def boyer_phi(i_v, phi_m=0.585):
    return phi_m / (1 + np.sqrt(i_v))


def eta_inf(phi):
    return (1 - phi / 0.68) ** (-2.4 * 0.68)

