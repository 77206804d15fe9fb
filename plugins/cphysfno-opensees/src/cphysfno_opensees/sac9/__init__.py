"""The SAC Los Angeles nine-story steel moment frame of the paper's Example 3 (§5.3).

- :mod:`.sections`: the published data and the wide-flange section properties.
- :mod:`.model`: the frame built in OpenSees, and its eigenvalues.
- :mod:`.interior`: the elastic interior sections of its members and their stresses.
- :mod:`.elastic`: the exact nine-DOF model of the frame while no steel yields.
- :mod:`.phases`: the elastic phases of an analysis taken from that model.
- :mod:`.analysis`: one record's time-history analysis and the solver settings.
- :mod:`.structure`: :class:`~.structure.Sac9Frame`, the registered structure.
"""
