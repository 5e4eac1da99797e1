"""Code generated from ``derivations/`` by ``python -m derivations.codegen``; do not edit."""
