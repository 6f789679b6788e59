"""Layer ``contact``: rigid obstacles (signed distance, normal, its gradient), the penalty contact of the
static solver and the kinematic contact of the explicit solver (§6.3).

Imports from ``model`` and below.
"""
