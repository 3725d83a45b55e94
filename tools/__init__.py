"""libg2p's tools that are Python: the training recipe (tools/training)."""
