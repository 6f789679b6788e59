"""Fabric data as laboratories report it: KES-F and FAST values converted to the model's rigidities
(:mod:`.lab`) and the library of published fabrics (:mod:`.library`). Layer: above ``material``."""
