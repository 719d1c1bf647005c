"""What a file says about every number measured in it: the warnings that
belong to the file and its encoding, not to one chip (a lossy codec's
loss, values gamma-encoded or taken as linear, an RGB photo's luminance).

``measure`` and ``scan`` both add these, from this one function, to every
result they give for the file (a scan to each edge it accepts), so that
one edge carries one set of warnings whichever command measured it.  The
chip's own warnings (clipping, sharpening, blocks seen in the pixels, a
mask) come from the pipeline both run (:mod:`imgmtf.estimate.pipeline`).
"""
from __future__ import annotations


def file_notes(raster, transfer: str = "linear", alpha_ignored: bool = False) -> list[str]:
    """The warnings every result from ``raster`` (:class:`imgmtf.io.Raster`,
    a band or the luminance of one file, or a window of it) must carry,
    measured with the ``transfer`` curve ("linear", "srgb", "gamma:G").

    Parameters
    ----------
    raster : imgmtf.io.Raster
        What was read: its band, type, compression and provenance.
    transfer : str, optional
        How the stored values were taken (:mod:`imgmtf.transfer`).
    alpha_ignored : bool, optional
        The file holds an alpha band that the luminance leaves out.

    Returns
    -------
    list of str
        The notes, in the order results list them.

    Examples
    --------
    >>> import numpy as np
    >>> from imgmtf.io import Raster
    >>> raster = Raster(np.zeros((4, 4)), "edge.jpg", band=1, gsd_m=None, dtype="uint8", compression="JPEG")
    >>> [note.split(":")[0] for note in file_notes(raster)]
    ['the file is stored with JPEG compression', '8-bit values are measured as stored, taken as linear']
    """
    notes = []
    if raster.band == "luminance":
        # a photo's stored values are gamma-encoded: their edge is not the light's, and the MTF differs
        encoding = ("gamma-encoded as stored (not linearised: the sRGB or a gamma transfer curve linearises "
                    "them)" if transfer == "linear" else f"then linearised ({transfer}: exact "
                    "for a grey target, whose channels are equal)")
        notes.append(f"measured on the Rec. 709 luminance of the stored RGB values, {encoding}"
                     + (", alpha ignored" if alpha_ignored else ""))
    if raster.compression:
        notes.append(f"the file is stored with {raster.compression} compression: the MTF includes the codec's loss "
                     "(measure an uncompressed copy for the system's own)")
    # (an RGB file's luminance carries its own note of the encoding, above)
    if raster.dtype == "uint8" and transfer == "linear" and raster.provenance is None and raster.band != "luminance":
        notes.append("8-bit values are measured as stored, taken as linear: if the image is gamma-encoded "
                     "(sRGB, as most 8-bit camera images are) the MTF reads wrong; linearise it with the sRGB "
                     "or a gamma transfer curve (MTF Mapper assumes sRGB for 8-bit input, Imatest its "
                     "gamma setting)")
    return notes
