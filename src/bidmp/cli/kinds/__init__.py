"""The command line's adapters of the model kinds learned from several demonstrations, one module
per kind, each named by its kind's entry in :mod:`bidmp.primitives.registry` (``cli``): what
``bidmp fit``'s options mean for it and how ``bidmp rollout`` conditions it. Each module holds
``ADAPTER``, an object with ``fit_takes`` and ``rollout_takes`` (the option names it acts on),
``learn(args, cls, demos, stamps, units)`` and ``roll(args, model, goal, via)``."""
