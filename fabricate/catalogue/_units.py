"""Unit conversions the catalogue's datasheets need, each exact by definition (no measured constant)."""

from __future__ import annotations

G_N = 9.80665  # standard gravity, m/s², exact (3rd CGPM 1901; ISO 80000-3): 1 kgf = 9.80665 N
KGF_CM_NMM = G_N * 10.0  # 1 kgf·cm in N·mm (1 cm = 10 mm)
KGF_MM_NMM = G_N  # 1 kg·mm (Pololu's "kg⋅mm", i.e. kgf·mm) in N·mm
GF_CM_NMM = G_N * 10.0 / 1000.0  # 1 gf·cm in N·mm (1 gf = 1/1000 kgf)
INCH_MM = 25.4  # exact: international yard and pound agreement, 1959
PSI_MPA = 0.45359237 * G_N / INCH_MM**2  # 1 psi in MPa, exact: 1 lb = 0.45359237 kg (1959 agreement)
KSI_MPA = 1000.0 * PSI_MPA  # 1 ksi in MPa


def rpm_to_deg_s(rpm: float) -> float:
    """Revolutions per minute to degrees per second (360° a turn, 60 s a minute)."""
    return rpm * 360.0 / 60.0


def s_per_60deg_to_deg_s(seconds: float) -> float:
    """A hobby-servo speed given as the time for 60° of travel, in degrees per second."""
    return 60.0 / seconds
