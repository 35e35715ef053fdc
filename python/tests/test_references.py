"""fdsusp.references: the published fits at points worked out by hand."""
import math

import numpy as np
import pytest

from fdsusp import references as R


def test_dilute_limits():
    assert R.zarraga_eta(0.0) == pytest.approx(1.0)
    assert R.eta_inf(0.0) == pytest.approx(1.0)
    assert R.morris_boulay_eta_n(0.0) == 0.0
    assert R.boyer_phi(0.0) == pytest.approx(0.585)


def test_known_points():
    assert R.zarraga_eta(0.31) == pytest.approx(math.exp(-2.34 * 0.31) * 8)        # 1 - 0.31/0.62 = 1/2
    assert R.eta_inf(0.34) == pytest.approx(2 ** (2.4 * 0.68))
    n1, n2 = R.dai_normal(0.5)
    assert (n1, n2) == (pytest.approx(-0.1), pytest.approx(-0.55))
    assert R.morris_boulay_eta_n(0.34) == pytest.approx(0.75)                      # phi = phi_m / 2
    assert R.morris_boulay_eta_n(0.29, 1.13, 0.58) == pytest.approx(1.13)
    assert R.boyer_phi(1.0) == pytest.approx(0.585 / 2)
    assert R.boyer_mu(0.005) == pytest.approx(0.32 + 0.19 + 0.005 + 2.5 * 0.585 * math.sqrt(0.005))


def test_arrays():
    phi = np.linspace(0.1, 0.5, 5)
    assert R.zarraga_eta(phi).shape == (5,)
    assert np.all(np.diff(R.eta_inf(phi)) > 0)
