"""Studies built on the simulators: parameter sweeps (:mod:`.sweep`), the largest
recoverable perturbation (:mod:`.recovery`) and identification of the gains from
measured angles (:mod:`.identification`). Each module is imported on first use."""
