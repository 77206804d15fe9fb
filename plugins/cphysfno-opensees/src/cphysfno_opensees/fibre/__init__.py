"""Compiled fibre-section column analysis: uniaxial materials, sections and force-based
elements in numba, checked against their OpenSees counterparts.

- :mod:`.steel02`, :mod:`.concrete04`: OpenSees' uniaxial materials of those names, each
  with its parameters (:class:`~.steel02.Steel02Parameters`,
  :class:`~.concrete04.Concrete04Parameters`) and its compiled law.
- :mod:`.material`: the protocol of those parameter classes.
- :mod:`.section`: fibre sections in three dimensions, a group of fibres per material.
- :mod:`.columns`: force-based columns fixed at their base: data, state, kinematics.
- :mod:`.state_determination`: the compiled state determination of those columns.
- :mod:`.dynamics`: static and Newmark analyses of a linear structure on such columns.
"""
