"""Names the command line offers before it loads the library (``fpdesign --help`` imports no numpy).

Each is defined here once and imported by the module that uses it.
"""

NOISE_CHOICES = ("auto", "residual", "design")   # calibrate --noise: where sigma_V comes from
SCHEMES = ("paper", "4", "9", "grid")             # calibration load schemes
