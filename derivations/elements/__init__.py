"""Element derivations, one module per element family, found by :mod:`derivations.registry` (each
declares ``ELEMENT``, a :class:`derivations.records.Element`, and ``derive()``)."""
