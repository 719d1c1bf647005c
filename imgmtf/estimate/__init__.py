"""The estimators: what a chip tells us.

Seed detection (:mod:`.detection`), per-row edge fits (:mod:`.fermi`) and
the target line (:mod:`.geometry`), profile resampling
(:mod:`.resampling`), spectra and figures (:mod:`.spectrum`), confidence
intervals (:mod:`.intervals`), and the edge and pulse estimators built on
them (:mod:`.edge`, :mod:`.pulse`, :mod:`.results`).
"""
