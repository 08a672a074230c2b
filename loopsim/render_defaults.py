"""Defaults and bounds of the files loopsim draws beyond figures: animations of a run
(``loopsim animate``, ``figures.animation``) and the HTML report of a sweep (``loopsim
report``, ``sweep_report``).  Plain constants, importable without NumPy, so that
``loopsim --help`` can show them; no kernel reads them, so editing them leaves the
compiled kernels' cache valid."""

#: ``loopsim animate``: the default most frames (evenly spaced stored snapshots), frames
#: per second and dots per inch (the docs' three GIFs of 60 frames: 290-630 kB).
ANIMATION_FRAMES, ANIMATION_FPS, ANIMATION_DPI = 60, 10, 80
#: Their bounds: a GIF grows with frames x dpi².
ANIMATION_MAX_FRAMES, ANIMATION_MAX_FPS, ANIMATION_DPI_RANGE = 600, 60, (30, 200)
#: ``loopsim report``: the costliest cases listed by default, and the resolution of the
#: embedded figures (dots per inch).
REPORT_COSTLIEST, REPORT_DPI = 10, 90
