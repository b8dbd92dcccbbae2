"""Layer 6, the analysis front doors: each checks its settings, packs the model, makes one
call into the core and turns the outputs into a result, warnings or a typed exception.

kinematics, inverse dynamics, forward dynamics, statics, the one-step kinematic stepper, the
degree-of-freedom analysis, Phi/J/nu/gamma at a state, and the export for ``mbd2d-solve``.
"""
