"""The optimal control problems of the thesis, one formulation per module.

Each module holds a frozen spec, the ``build`` that turns it into a :class:`gaitlib.ocp.Problem`
(or a CasADi NLP), the formulation's version string ``FORMULATION`` (part of every cache key,
see :mod:`gaitlib.cache`) and the solution class with its post-processing:

``gait``   the gait cycle of Ch 2, 4-7 (SK / MSK / NMSK, tracking and predictive costs)
"""
