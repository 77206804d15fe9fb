"""OpenSees structures for cphysfno."""
