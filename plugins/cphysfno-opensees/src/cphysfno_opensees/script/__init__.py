"""``opensees-model``: a user's own OpenSeesPy script as a cphysfno structure.

- :mod:`.source`: the script, executed as a module, and :class:`~.source.ScriptError`.
- :mod:`.model`: the model built by the script, under gravity, set up for a record.
- :mod:`.probe`: the constraint handler, Rayleigh factors and linear equations found
  for the model before any record (in a worker process).
- :mod:`.analysis`: one record's time-history analysis.
- :mod:`.structure`: :class:`~.structure.OpenSeesModel`, the registered structure.
"""
