"""The optimal control problems of the thesis, one formulation per module.

Each module holds a frozen spec, the ``build`` that turns it into a :class:`gaitlib.ocp.Problem`
(or a CasADi NLP), the formulation's version string ``FORMULATION`` (part of every cache key,
see :mod:`gaitlib.cache`) and the solution class with its post-processing:

``gait``   the gait cycle of Ch 2, 4-7 (SK / MSK / NMSK, tracking and predictive costs)
``jump``   the vertical jumps of Ch 3 (toeless, toe, ellipsoid contact)
``contact_id``  Ch 4: approach (a), contact parameters on fixed kinematics; approaches (b)/(c),
           ``gait`` with the parameters free, reached by a residual-bound continuation
``mtg_id`` Ch 5 MTG identification: the 42 fitting parameters on the data's joint motion
"""
