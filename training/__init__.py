"""Training the proposal scorer: the label dataset (PyG, from the ``labels`` stage's Parquet), the
focal loss, the MLflow-tracked training loop and the model card writer.

Run from the checkout (``python -m training.train``, the DVC ``train`` stage); not installed. The
network itself and what inference needs (model, encoding, checkpoint loading, the ranker) are in
`zonegraph.network`.
"""
