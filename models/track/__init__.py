"""Track dynamics: infinite Euler beam on a Kelvin foundation with axial force (thesis Ch. 3, App. A).

Public names:

* :class:`Beam` — parameters, N_cr, v_cr, damping ratio, delegates to the analyses;
* :func:`hetenyi_deflection` — (3.19); :func:`static_deflection` — with axial force;
* :func:`moving_load` → :class:`MovingLoadSolution` — steady state (3.26), closed form or Fourier;
* :func:`impulse_response_at_load` — (3.20)–(3.24), closed form or numerical inversion;
* :func:`transient` → :class:`TransientSolution` — load cases (i)–(vi) of §3.2.2;
* :func:`lumped` → :class:`LumpedTrack` — (4.33)–(4.39) and the roll terms of (4.49);
* :func:`dynamic_amplification` — maximum and lag over v/v_cr, c/c_cr, N/N_cr;
* :func:`irregularity_spectrum` → :class:`RationalSpectrum` (FRA classes 1–6, ERRI B176) or, with
  ``.from_table(path)``, :class:`TabulatedSpectrum` — random track geometry (:mod:`.spectra`, docs/ride.md).
"""

from railopt.models.track.amplification import dynamic_amplification
from railopt.models.track.beam import Beam, hetenyi_deflection
from railopt.models.track.impulse import impulse_constant, impulse_response_at_load, printed_impulse_constant
from railopt.models.track.lumped import LumpedTrack, lumped
from railopt.models.track.moving_load import (
    ClosedFormSolution,
    MovingLoadSolution,
    characteristic_roots,
    closed_form_solution,
    fourier_deflection,
    moving_load,
    static_deflection,
)
from railopt.models.track.parameters import RAIL_115RE, RAIL_132RE, RailSection, f0_table, wooden_tie_track
from railopt.models.track.spectra import RationalSpectrum, TabulatedSpectrum, irregularity_spectrum
from railopt.models.track.transient import (
    DistributedImpulse,
    ImpulseLoad,
    MovingLoad,
    SuddenLoad,
    TransientSolution,
    transient,
)

__all__ = [
    "Beam",
    "ClosedFormSolution",
    "DistributedImpulse",
    "ImpulseLoad",
    "LumpedTrack",
    "MovingLoad",
    "MovingLoadSolution",
    "RAIL_115RE",
    "RAIL_132RE",
    "RailSection",
    "RationalSpectrum",
    "SuddenLoad",
    "TabulatedSpectrum",
    "TransientSolution",
    "characteristic_roots",
    "closed_form_solution",
    "dynamic_amplification",
    "f0_table",
    "fourier_deflection",
    "hetenyi_deflection",
    "impulse_constant",
    "impulse_response_at_load",
    "irregularity_spectrum",
    "lumped",
    "moving_load",
    "printed_impulse_constant",
    "static_deflection",
    "transient",
    "wooden_tie_track",
]
