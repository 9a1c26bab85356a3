"""Colour of daylight: Planck's black-body radiance (Lee 2017, 4.1.2, Eq. 4.7) seen through a
camera's red, green and blue sensitivities, white-balanced once (a fixed camera, as Lee fixed
his in 4.2)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "BOLTZMANN_K",
    "LIGHT_C",
    "PLANCK_H",
    "SENSITIVITY",
    "WAVELENGTHS",
    "blackbody_bgr",
    "planck",
]

PLANCK_H = 6.62607015e-34  # J s
LIGHT_C = 2.99792458e8  # m / s
BOLTZMANN_K = 1.380649e-23  # J / K
#: Visible wavelengths (m) and the camera's Gaussian channel sensitivities (B, G, R; OpenCV
#: order): peaks at 460, 540 and 600 nm, 40 nm wide, a generic CMOS sensor.
WAVELENGTHS = np.linspace(400e-9, 700e-9, 61)
_PEAKS = np.array([460e-9, 540e-9, 600e-9])
SENSITIVITY = np.exp(-0.5 * ((WAVELENGTHS[None, :] - _PEAKS[:, None]) / 40e-9) ** 2)


def planck(wavelength, temperature) -> np.ndarray:
    """Eq. 4.7: spectral radiance ``2 h c^2 / lambda^5 / (exp(h c / (lambda k_B T)) - 1)`` in
    W sr^-1 m^-3 of a black body at ``temperature`` kelvin."""
    lam = np.asarray(wavelength, np.float64)
    exponent = PLANCK_H * LIGHT_C / (lam * BOLTZMANN_K * np.asarray(temperature, np.float64))
    return 2 * PLANCK_H * LIGHT_C**2 / lam**5 / np.expm1(exponent)


def blackbody_bgr(temperature: float, white_balance: float = 5500.0) -> np.ndarray:
    """Camera BGR of a black body at ``temperature`` K, relative to one at ``white_balance`` K
    (which gives (1, 1, 1)), with the green channel of both normalised to 1: the tint only."""

    def response(t: float) -> np.ndarray:
        raw = SENSITIVITY @ planck(WAVELENGTHS, t)
        return raw / raw[1]

    return response(temperature) / response(white_balance)
