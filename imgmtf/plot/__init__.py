"""Figures, one module per subject: the sensor model, a measurement, a sensor
fit, a scene scan, the 2-D MTF's sections, a campaign's trends, a restoration and the paper's study.
Each function draws on ``ax`` (a new figure when None) and returns the figure;
nothing here touches pyplot's global state, so the figures render with the Agg
canvas whatever the session's backend."""
from .campaign import plot_campaign, plot_trend
from .fit import plot_fit, plot_fit_edge, plot_fit_lsf, plot_fit_residuals
from .lens import plot_lens_mtf, plot_lens_mtf50, plot_lens_profile
from .measurement import plot_locations, plot_lsf, plot_measurement, plot_mtf, plot_profile
from .paper import plot_estimates, plot_ground_noise_layers, plot_noise_sweep, plot_threshold
from .point_scan import plot_point_scan
from .points import plot_point_mtf, plot_point_mtf2d, plot_point_psf, plot_point_sources, plot_points
from .restore import plot_restoration, plot_restore_tradeoff, plot_restored_edge, plot_restored_mtf
from .scan import plot_scan
from .sections import plot_sections
from .sensor import plot_psf, plot_sensor, plot_sensor_lsf, plot_sensor_mtf
from .star import plot_star, plot_star_directions, plot_star_image, plot_star_mtf

__all__ = ["plot_campaign", "plot_estimates", "plot_fit", "plot_fit_edge", "plot_fit_lsf", "plot_fit_residuals",
           "plot_ground_noise_layers",
           "plot_lens_mtf", "plot_lens_mtf50", "plot_lens_profile",
           "plot_locations", "plot_lsf", "plot_measurement", "plot_mtf",
           "plot_noise_sweep", "plot_point_mtf", "plot_point_mtf2d", "plot_point_psf", "plot_point_sources",
           "plot_points", "plot_profile", "plot_psf", "plot_restoration", "plot_restore_tradeoff",
           "plot_restored_edge", "plot_restored_mtf", "plot_scan", "plot_sections", "plot_sensor", "plot_sensor_lsf",
           "plot_sensor_mtf", "plot_star", "plot_star_directions", "plot_star_image", "plot_star_mtf",
           "plot_threshold", "plot_trend"]
__all__ += ["plot_point_scan"]
