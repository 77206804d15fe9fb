"""Each ground-motion source passes the conformance checks."""

import warnings

from cphysfno_core.testing import check_ground_motion_source

from cphysfno_ground_motions import GroundMotionWarning, Recorded, SpectrumCompatible, WhiteNoise


def test_white_noise_conforms():
    check_ground_motion_source(WhiteNoise(duration=5.0))


def test_spectrum_compatible_conforms():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GroundMotionWarning)  # per-record misfit notes
        check_ground_motion_source(SpectrumCompatible(duration=10.0))


def test_recorded_fema_set_conforms():
    check_ground_motion_source(Recorded(source="fema-p695", dt=0.01, duration=20.0))
