"""A calibration campaign: every acquisition of a site kept in one
GeoPackage store, trended over time and reported.

``acquisitions`` (what a measured file is: time, platform, band...),
``store`` (the GeoPackage), ``trend`` (drift per year) and ``report``
(the self-contained HTML page).
"""
