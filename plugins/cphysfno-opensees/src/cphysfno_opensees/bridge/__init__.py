"""The Auburn Ravine type bridge of the paper's Example 2 (§5.2).

- :mod:`.design`: the calibrated quantities (geometry, materials, masses, damping).
- :mod:`.numerics`: how the columns are discretised and the equations solved.
- :mod:`.column`: the columns' fibre section and its materials, as data.
- :mod:`.model`: the bridge built in OpenSees, under gravity.
- :mod:`.linear`: its linear representation, condensed from the elastic OpenSees model.
- :mod:`.analysis`: one record's time-history analysis in OpenSees.
- :mod:`.compiled`: the same analysis in compiled code (the default engine).
- :mod:`.structure`: :class:`~.structure.AuburnRavineBridge`, the registered structure.
"""
