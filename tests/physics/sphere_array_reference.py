"""The drag of a simple cubic array of spheres, independent of the code: shared by
test_fd_sphere_array (a free sphere pulled by a force) and test_fd_moving_sphere (a sphere dragged
at a prescribed velocity). K = F / (6 pi eta a U) at solid fraction phi, U the sphere's velocity
relative to the box-mean velocity (fluid and spheres together).
 - Sangani & Acrivos (1982, Int. J. Multiphase Flow 8:343) series for the simple cubic array,
   K = 1/(1 - 1.7601 chi + phi - 1.5593 phi^2 + 3.9799 phi^(8/3) - 3.0734 phi^(10/3)), chi = phi^(1/3);
   it reproduces Zick & Homsy (1982, JFM 115:13, Table 2) to 0.03 % at phi = 0.027, 0.064, 0.125;
 - Zick & Homsy's K = 7.442 at phi = 0.216 (the series gives 7.384 there, -0.8 %); above
   phi = 0.13 the reference is the series scaled by that ratio (uncertainty ~0.5 % at 0.19)."""


def k_series(phi):
    chi = phi ** (1 / 3)
    return 1 / (1 - 1.7601 * chi + phi - 1.5593 * phi ** 2 + 3.9799 * phi ** (8 / 3) - 3.0734 * phi ** (10 / 3))


def k_reference(phi):
    if phi <= 0.13:
        return k_series(phi)
    return k_series(phi) * 7.442 / k_series(0.216)
