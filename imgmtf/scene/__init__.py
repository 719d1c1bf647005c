"""Scanning a scene for targets: ``imgmtf scan``.

1. detect (:mod:`.detect`): the scene is read tile by tile (windowed reads:
   a large scene is never loaded whole), scaled to 8 bits with levels taken
   from a decimated overview, and OpenCV's line segment detector (LSD)
   finds straight segments in each tile; collinear pieces (across tiles
   too) are merged; two parallel segments a few pixels apart are the two
   sides of a bar, one pulse candidate (and, for edges, a rejection: a bar
   is not an edge);
2. screen (:mod:`.screen`): a candidate shorter than ``min_length_px`` or
   tilted less than ``MIN_ANGLE_DEG`` from an image axis or more than
   ``MAX_ANGLE_DEG`` is rejected before it is read;
3. measure (:mod:`.measure`): an axis-aligned ROI around each candidate
   (``margin_px`` beyond it across, its ends trimmed) is read and measured;
   the estimator's own refusals (another edge in the ROI, saturation,
   border...) become the rejection reason, and an accepted target must
   have uniform sides and a straight line (:class:`.settings.ScanSettings`);
   accepted targets are ranked by the width of their MTF-at-Nyquist
   confidence interval, which grows as SNR, length or straightness fall;
4. export (:mod:`.export`): CSV, GeoJSON and an overview figure.

Every candidate becomes a :class:`imgmtf.records.Record` with ``status``
(accepted/rejected), ``reason`` and, in its ``site``, ``id``, ``rank``,
the segment in pixels (``x0_px``...) and, when georeferenced, in map
coordinates.  An unexpected failure on one candidate rejects it (reason
``internal``), never the scan.
"""
