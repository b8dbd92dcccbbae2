"""Layer 3, the core binding: the model description packed into the core's flat tables
(:mod:`.pack`, :mod:`.tables`), the calls into the compiled core (:mod:`.core`, the only
module that imports ``mbd2d._core``) and the core's status codes (:mod:`.status`)."""
