"""Sweeps and Monte Carlo of cases on dask.distributed (``riskassess sweep``): run specs
(:mod:`.spec`), the results store (:mod:`.store`), the runner (:mod:`.runner`) and the safe
impact envelope (:mod:`.envelope`)."""
