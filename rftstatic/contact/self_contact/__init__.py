"""Self-contact of the sheet (issue 15): distances between its own elements (:mod:`.distance`), the
broad phase that finds the pairs (:mod:`.broad_phase`) and the penalty law with its step bound
(:mod:`.law`)."""
