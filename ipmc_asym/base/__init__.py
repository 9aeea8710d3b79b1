"""Foundation: the registry of models and fidelities, numerical settings, unit parsing and
the progress helper, strict JSON. Pure Python; imports nothing else of the package."""
