"""Compiled fibre-section column analysis: uniaxial materials, sections and force-based
elements in numba, checked against their OpenSees counterparts."""
