"""The models the diagnosis effects load: plant descriptions (``plant``, ``towing_plant``), their
compiled equations of motion (``dynamics``, ``towing_dynamics``), the record channels (``channels``)
and the choice of plant by scenario (``scenario``).

It imports no effect and no catalog: the effect plug-ins (``riskassess/diagnosis/effects/``) build on
it and the engine (``riskassess/diagnosis/*``) uses both, so the plug-ins and the engine form no cycle.
"""
