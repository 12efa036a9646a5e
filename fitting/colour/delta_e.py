"""
Delta E 2000
============

-   :func:`delta_E_2000`: CIE Delta E 2000 between CIE Lab arrays
    (colour-science's, to the bit).
-   :func:`delta_E_map`: the same per sample between two linear ACEScg arrays.
-   :func:`de2000_weights`: the first-order CIEDE2000 metric at a reference
    colour, the linearisation the ``de2000`` fitting objective is built on.

Lab uses the ACES white as reference white
(:func:`fitting.colour.colorimetry.ACEScg_to_Lab`).

References
----------
Sharma, G., Wu, W., & Dalal, E. N. (2005). The CIEDE2000 color-difference
formula. Color Research & Application, 30(1), 21-30.
"""

from __future__ import annotations

import numpy as np

from .colorimetry import ACEScg_to_Lab

__all__ = ["delta_E_2000", "delta_E_2000_gradient", "delta_E_2000_components", "delta_E_map", "de2000_weights"]


def delta_E_2000(Lab_1, Lab_2) -> np.ndarray:
    """
    CIE Delta E 2000 between two CIE Lab arrays (..., 3), L in [0, 100]
    (Sharma et al. 2005, Eq. 1-22): colour-science's ``delta_E_CIE2000``
    written out with the same operations in the same order, so the same
    numbers to the bit (tested), without importing colour-science (with
    scipy, most of a command's start) or its per-call domain handling.
    """
    Lab_1 = np.asarray(Lab_1, dtype=np.float64)
    Lab_2 = np.asarray(Lab_2, dtype=np.float64)
    L_1, a_1, b_1 = Lab_1[..., 0], Lab_1[..., 1], Lab_1[..., 2]
    L_2, a_2, b_2 = Lab_2[..., 0], Lab_2[..., 1], Lab_2[..., 2]
    C_bar_ab = (np.hypot(a_1, b_1) + np.hypot(a_2, b_2)) / 2
    C_bar_ab_7 = C_bar_ab**7
    G = 0.5 * (1 - np.sqrt(C_bar_ab_7 / (C_bar_ab_7 + 25**7)))
    a_p_1, a_p_2 = (1 + G) * a_1, (1 + G) * a_2
    C_p_1, C_p_2 = np.hypot(a_p_1, b_1), np.hypot(a_p_2, b_2)
    # The hue angle of an achromatic colour is 0 by convention.
    h_p_1 = np.where((b_1 == 0) & (a_p_1 == 0), 0, np.degrees(np.arctan2(b_1, a_p_1)) % 360)
    h_p_2 = np.where((b_2 == 0) & (a_p_2 == 0), 0, np.degrees(np.arctan2(b_2, a_p_2)) % 360)
    delta_L_p = L_2 - L_1
    delta_C_p = C_p_2 - C_p_1
    h_p_2_s_1 = h_p_2 - h_p_1
    C_p_1_m_2 = C_p_1 * C_p_2
    # colour-science's np.select (the first condition that holds, else 0) as
    # nested selections: the same values, a fraction of the time.
    delta_h_p = np.where(
        C_p_1_m_2 == 0,
        0,
        np.where(
            np.fabs(h_p_2_s_1) <= 180,
            h_p_2_s_1,
            np.where(h_p_2_s_1 > 180, h_p_2_s_1 - 360, np.where(h_p_2_s_1 < -180, h_p_2_s_1 + 360, 0)),
        ),
    )
    delta_H_p = 2 * np.sqrt(C_p_1_m_2) * np.sin(np.deg2rad(delta_h_p / 2))
    L_bar_p = (L_1 + L_2) / 2
    C_bar_p = (C_p_1 + C_p_2) / 2
    a_h_p_1_s_2 = np.fabs(h_p_1 - h_p_2)
    h_p_1_a_2 = h_p_1 + h_p_2
    h_bar_p = np.where(
        C_p_1_m_2 == 0,
        h_p_1_a_2,
        np.where(
            a_h_p_1_s_2 <= 180,
            h_p_1_a_2 / 2,
            np.where(
                (a_h_p_1_s_2 > 180) & (h_p_1_a_2 < 360),
                (h_p_1_a_2 + 360) / 2,
                np.where((a_h_p_1_s_2 > 180) & (h_p_1_a_2 >= 360), (h_p_1_a_2 - 360) / 2, 0),
            ),
        ),
    )
    T = (
        1
        - 0.17 * np.cos(np.deg2rad(h_bar_p - 30))
        + 0.24 * np.cos(np.deg2rad(2 * h_bar_p))
        + 0.32 * np.cos(np.deg2rad(3 * h_bar_p + 6))
        - 0.20 * np.cos(np.deg2rad(4 * h_bar_p - 63))
    )
    delta_theta = 30 * np.exp(-(((h_bar_p - 275) / 25) ** 2))
    C_bar_p_7 = C_bar_p**7
    R_C = 2 * np.sqrt(C_bar_p_7 / (C_bar_p_7 + 25**7))
    L_bar_p_2 = (L_bar_p - 50) ** 2
    S_L = 1 + ((0.015 * L_bar_p_2) / np.sqrt(20 + L_bar_p_2))
    S_C = 1 + 0.045 * C_bar_p
    S_H = 1 + 0.015 * C_bar_p * T
    R_T = -np.sin(np.deg2rad(2 * delta_theta)) * R_C
    # k_L = k_C = k_H = 1 (reference conditions, not textiles).
    return np.sqrt(
        (delta_L_p / S_L) ** 2
        + (delta_C_p / S_C) ** 2
        + (delta_H_p / S_H) ** 2
        + R_T * (delta_C_p / S_C) * (delta_H_p / S_H)
    )


def delta_E_map(reference_RGB, model_RGB) -> np.ndarray:
    """Delta E 2000 per sample between two linear ACEScg arrays (..., 3), broadcast."""
    return delta_E_2000(ACEScg_to_Lab(reference_RGB), ACEScg_to_Lab(model_RGB))


def de2000_weights(Lab_ref: np.ndarray) -> np.ndarray:
    """
    Per-sample 3 x 3 maps A with ``|A dLab|`` the CIEDE2000 difference to
    first order around the reference colour (Sharma et al. 2005, Eq. 1-22):
    rows dL'/S_L, dC'/S_C + R_T/2 dH'/S_H and sqrt(1 - R_T^2/4) dH'/S_H.
    """
    L, a, b = Lab_ref[:, 0], Lab_ref[:, 1], Lab_ref[:, 2]
    C = np.hypot(a, b)
    C7 = C**7
    G = 0.5 * (1.0 - np.sqrt(C7 / (C7 + 25.0**7)))
    a1 = (1.0 + G) * a
    C1 = np.hypot(a1, b)
    h = np.arctan2(b, a1)
    h_deg = np.degrees(h) % 360.0
    # Achromatic colours have no hue direction: any orthonormal pair serves.
    safe = C1 > 1e-9
    cos_h = np.where(safe, a1 / np.where(safe, C1, 1.0), 1.0)
    sin_h = np.where(safe, b / np.where(safe, C1, 1.0), 0.0)
    SL = 1.0 + 0.015 * (L - 50.0) ** 2 / np.sqrt(20.0 + (L - 50.0) ** 2)
    SC = 1.0 + 0.045 * C1
    T = (
        1.0
        - 0.17 * np.cos(np.radians(h_deg - 30.0))
        + 0.24 * np.cos(np.radians(2.0 * h_deg))
        + 0.32 * np.cos(np.radians(3.0 * h_deg + 6.0))
        - 0.20 * np.cos(np.radians(4.0 * h_deg - 63.0))
    )
    SH = 1.0 + 0.015 * C1 * T
    C17 = C1**7
    RT = (
        -np.sin(np.radians(2.0 * 30.0 * np.exp(-(((h_deg - 275.0) / 25.0) ** 2))))
        * 2.0
        * np.sqrt(C17 / (C17 + 25.0**7))
    )
    A = np.zeros((L.size, 3, 3))
    A[:, 0, 0] = 1.0 / SL
    # dC' = cos_h da' + sin_h db, dH' = -sin_h da' + cos_h db, da' = (1 + G) da.
    dC = np.stack([np.zeros_like(L), (1.0 + G) * cos_h, sin_h], axis=-1)
    dH = np.stack([np.zeros_like(L), -(1.0 + G) * sin_h, cos_h], axis=-1)
    A[:, 1, :] = dC / SC[:, None] + (RT / 2.0)[:, None] * dH / SH[:, None]
    A[:, 2, :] = np.sqrt(np.clip(1.0 - RT**2 / 4.0, 0.0, 1.0))[:, None] * dH / SH[:, None]
    return A


def delta_E_2000_gradient(Lab_1, Lab_2) -> tuple[np.ndarray, np.ndarray]:
    """
    :func:`delta_E_2000` (...,) and its gradient with respect to ``Lab_2``
    (..., 3), from :func:`delta_E_2000_components`. Where the difference is
    0 (not differentiable) the gradient is 0.
    """
    v, dv = delta_E_2000_components(Lab_1, Lab_2)
    dE = np.sqrt(np.sum(v * v, axis=-1))
    grad = np.einsum("...i,...ij->...j", v, dv) / np.where(dE == 0, 1.0, dE)[..., None]
    return dE, np.where((dE > 0)[..., None], grad, 0.0)


def delta_E_2000_components(Lab_1, Lab_2) -> tuple[np.ndarray, np.ndarray]:
    """
    A vector v (..., 3) whose length is :func:`delta_E_2000` (to rounding),
    and its Jacobian with respect to ``Lab_2`` (..., 3, 3): with
    :math:`l = \\Delta L'/S_L`, :math:`c = \\Delta C'/S_C`,
    :math:`h = \\Delta H'/S_H`, the sum :math:`l^2 + c^2 + h^2 + R_T c h` is
    :math:`|v|^2` for :math:`v = (l, c + R_T h / 2, h \\sqrt{1 - R_T^2/4})`
    (:math:`|R_T| < 2`). Least squares on v minimise the same sum of
    squared Delta E as on Delta E itself, with residuals that are smooth
    where a Delta E is 0 (a Gauss-Newton model that holds there).
    Derivatives in forward mode through the formula of :func:`delta_E_2000`
    (Sharma et al. 2005, Eq. 1-22), the tangent of each intermediate
    carried beside it; at an achromatic colour the hue terms carry none.
    """
    Lab_1 = np.asarray(Lab_1, dtype=np.float64)
    Lab_2 = np.asarray(Lab_2, dtype=np.float64)
    L_1, a_1, b_1 = Lab_1[..., 0], Lab_1[..., 1], Lab_1[..., 2]
    L_2, a_2, b_2 = Lab_2[..., 0], Lab_2[..., 1], Lab_2[..., 2]
    e = np.eye(3)
    dL_2, da_2, db_2 = e[0], e[1], e[2]  # tangents broadcast against (..., 3)
    P7 = 25.0**7

    def root_u(C):  # sqrt(C^7 / (C^7 + 25^7)) and its derivative in C
        C7 = C**7
        return np.sqrt(C7 / (C7 + P7)), 3.5 * C**2.5 * P7 / (C7 + P7) ** 1.5

    def safe(den):
        return np.where(den == 0, 1.0, den)

    C_1, C_2 = np.hypot(a_1, b_1), np.hypot(a_2, b_2)
    dC_2 = (a_2[..., None] * da_2 + b_2[..., None] * db_2) / safe(C_2)[..., None]
    C_bar = (C_1 + C_2) / 2
    dC_bar = dC_2 / 2
    r, dr = root_u(C_bar)
    G = 0.5 * (1 - r)
    dG = (-0.5 * dr)[..., None] * dC_bar
    a_p_1, a_p_2 = (1 + G) * a_1, (1 + G) * a_2
    da_p_1 = a_1[..., None] * dG
    da_p_2 = a_2[..., None] * dG + (1 + G)[..., None] * da_2
    C_p_1, C_p_2 = np.hypot(a_p_1, b_1), np.hypot(a_p_2, b_2)
    dC_p_1 = a_p_1[..., None] * da_p_1 / safe(C_p_1)[..., None]
    dC_p_2 = (a_p_2[..., None] * da_p_2 + b_2[..., None] * db_2) / safe(C_p_2)[..., None]
    deg = 180.0 / np.pi
    h_p_1 = np.where((b_1 == 0) & (a_p_1 == 0), 0, np.degrees(np.arctan2(b_1, a_p_1)) % 360)
    h_p_2 = np.where((b_2 == 0) & (a_p_2 == 0), 0, np.degrees(np.arctan2(b_2, a_p_2)) % 360)
    dh_p_1 = (deg * -b_1 / safe(C_p_1**2))[..., None] * da_p_1
    dh_p_2 = (deg / safe(C_p_2**2))[..., None] * (a_p_2[..., None] * db_2 - b_2[..., None] * da_p_2)
    h_p_2_s_1 = h_p_2 - h_p_1
    C_p_1_m_2 = C_p_1 * C_p_2
    dC_p_1_m_2 = C_p_2[..., None] * dC_p_1 + C_p_1[..., None] * dC_p_2
    chroma = (C_p_1_m_2 != 0)[..., None]
    delta_h_p = np.where(
        C_p_1_m_2 == 0,
        0,
        np.where(
            np.fabs(h_p_2_s_1) <= 180,
            h_p_2_s_1,
            np.where(h_p_2_s_1 > 180, h_p_2_s_1 - 360, np.where(h_p_2_s_1 < -180, h_p_2_s_1 + 360, 0)),
        ),
    )
    ddelta_h_p = np.where(chroma, dh_p_2 - dh_p_1, 0.0)
    root_m = np.sqrt(C_p_1_m_2)
    half = np.deg2rad(delta_h_p / 2)
    delta_H_p = 2 * root_m * np.sin(half)
    ddelta_H_p = np.where(
        chroma,
        (np.sin(half) / safe(root_m))[..., None] * dC_p_1_m_2 + (root_m * np.cos(half) / deg)[..., None] * ddelta_h_p,
        0.0,
    )
    L_bar_p = (L_1 + L_2) / 2
    C_bar_p = (C_p_1 + C_p_2) / 2
    dC_bar_p = (dC_p_1 + dC_p_2) / 2
    a_h_p_1_s_2 = np.fabs(h_p_1 - h_p_2)
    h_p_1_a_2 = h_p_1 + h_p_2
    h_bar_p = np.where(
        C_p_1_m_2 == 0,
        h_p_1_a_2,
        np.where(
            a_h_p_1_s_2 <= 180,
            h_p_1_a_2 / 2,
            np.where(
                (a_h_p_1_s_2 > 180) & (h_p_1_a_2 < 360),
                (h_p_1_a_2 + 360) / 2,
                np.where((a_h_p_1_s_2 > 180) & (h_p_1_a_2 >= 360), (h_p_1_a_2 - 360) / 2, 0),
            ),
        ),
    )
    dh_bar_p = np.where(chroma, (dh_p_1 + dh_p_2) / 2, dh_p_1 + dh_p_2)
    rad = np.deg2rad
    T = (
        1
        - 0.17 * np.cos(rad(h_bar_p - 30))
        + 0.24 * np.cos(rad(2 * h_bar_p))
        + 0.32 * np.cos(rad(3 * h_bar_p + 6))
        - 0.20 * np.cos(rad(4 * h_bar_p - 63))
    )
    dT_dh = (
        0.17 * np.sin(rad(h_bar_p - 30))
        - 0.48 * np.sin(rad(2 * h_bar_p))
        - 0.96 * np.sin(rad(3 * h_bar_p + 6))
        + 0.80 * np.sin(rad(4 * h_bar_p - 63))
    ) / deg
    dT = dT_dh[..., None] * dh_bar_p
    delta_theta = 30 * np.exp(-(((h_bar_p - 275) / 25) ** 2))
    ddelta_theta = (delta_theta * -2 * (h_bar_p - 275) / 625)[..., None] * dh_bar_p
    r_p, dr_p = root_u(C_bar_p)
    R_C = 2 * r_p
    dR_C = (2 * dr_p)[..., None] * dC_bar_p
    q = (L_bar_p - 50) ** 2
    S_L = 1 + ((0.015 * q) / np.sqrt(20 + q))
    dS_L = (0.015 * (20 + q / 2) / (20 + q) ** 1.5 * 2 * (L_bar_p - 50) / 2)[..., None] * dL_2
    S_C = 1 + 0.045 * C_bar_p
    dS_C = 0.045 * dC_bar_p
    S_H = 1 + 0.015 * C_bar_p * T
    dS_H = 0.015 * (T[..., None] * dC_bar_p + C_bar_p[..., None] * dT)
    R_T = -np.sin(rad(2 * delta_theta)) * R_C
    dR_T = (-np.cos(rad(2 * delta_theta)) * 2 / deg * R_C)[..., None] * ddelta_theta - np.sin(rad(2 * delta_theta))[
        ..., None
    ] * dR_C
    ell, c, h = (L_2 - L_1) / S_L, (C_p_2 - C_p_1) / S_C, delta_H_p / S_H
    dell = (dL_2 - ell[..., None] * dS_L) / S_L[..., None]
    dc = ((dC_p_2 - dC_p_1) - c[..., None] * dS_C) / S_C[..., None]
    dh = (ddelta_H_p - h[..., None] * dS_H) / S_H[..., None]
    s = np.sqrt(1 - R_T**2 / 4)
    v = np.stack([ell, c + R_T * h / 2, s * h], axis=-1)
    dv = np.stack(
        [
            dell,
            dc + (R_T / 2)[..., None] * dh + (h / 2)[..., None] * dR_T,
            s[..., None] * dh - (R_T * h / (4 * s))[..., None] * dR_T,
        ],
        axis=-2,
    )
    return v, dv
