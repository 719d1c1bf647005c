"""Fit a sensor's stages to the edge profiles of one or more images.

The parametric estimate (:func:`fit_edges`: arrays and measurements; the
public :func:`imgmtf.fit_sensor` reads files and calls it).  Each edge is
measured as usual (:func:`imgmtf.measure_edge`) for its geometry only:
every pixel's signed distance from the edge along its normal and its
value.  The model of the edge is then

    DN = L + (R - L) ESF(x - x0),

where ESF is the sensor's exact edge response along that edge's normal
(:meth:`imgmtf.Sensor.line_response`), and L, R (levels) and x0 (sub-pixel
offset) are the edge's own nuisance parameters.  All edges share the
stages' parameters, so an across-track and an along-track edge together
constrain both axes.  The parameters are fitted by bounded least squares
(``scipy.optimize.least_squares``, :meth:`_Model.solve`), each edge
weighted by the inverse of its noise, measured without the model (each
sample against the line through its two neighbours, :func:`profile_noise`).
The fit's residuals are those of the samples binned 1/32 px along the
normal (:func:`.data.bin_profile`), each bin's model its mean over the
bin's samples (to the third order, far below the noise) weighted by the
square root of its count: the samples' optimum from a third to a ninth of
the residuals; the reduced chi-square is still the samples'.

Identifiability, in three steps:

1. Axes.  An edge constrains only its own normal.  When no edge lies
   within 45 deg of the along-track axis, every along-track parameter that
   has an across-track twin is tied to it (a symmetric optic) and the
   others (motion) are held; likewise the other way round.
2. Coordinates.  Each parameter is fitted as its blur length in pixels
   raised to the power to which the low-frequency MTF responds (the square
   for widths, the length itself for diffraction), bounded from 0 (stage
   absent) to a few pixels; see :class:`imgmtf.sensor.stages.FitSpec`.
3. Holding.  After a fit, a parameter whose one-standard-error range is
   wider than ``DETERMINED_RELATIVE`` (50 %) of its blur length and than
   ``DETERMINED_PX`` (0.2 px) is not determined by the data: the best-known
   of those (detector first, optics last) is held at its starting value
   (a lag started from the edges' lean, :mod:`.seeds`, at none),
   and the fit is redone, until every free parameter is determined.  Then,
   best-known first, a parameter is held when freeing it gains less than
   ``LIKELIHOOD_RATIO`` in chi-square, keeping one free parameter on each
   axis an edge sees (one plainly needed, ``WALD_MARGIN`` times that by
   its Wald statistic, stays free without the trial refit).  Optics sigma, electronics cut-off and detector
   width shape the MTF alike, and such pairs are reported with their
   correlation.

The result reports each parameter with its standard error (from the
Jacobian, scaled up by the reduced chi-square when that exceeds 1), the
reduced chi-square, the model's MTF at Nyquist along each edge's normal
with a delta-method interval, the across- and along-track MTF at Nyquist
and MTF50, and a misfit warning when the residuals, binned along the
normal, show structure the noise cannot explain.
"""
from .data import EdgeImage, profile_noise
from .fitting import fit_edges
from .model import check_names
from .record import FitRecord, read_fit_record
from .results import EdgeFit, FittedParameter, SensorFit

__all__ = ["EdgeFit", "EdgeImage", "FitRecord", "FittedParameter", "SensorFit", "check_names", "fit_edges",
           "profile_noise", "read_fit_record"]
