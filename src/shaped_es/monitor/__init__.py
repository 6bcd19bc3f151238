"""What a run reports while it runs: the progress display (``progress.py``), TensorBoard tags
(``tensorboard.py``), Weights & Biases (``wandb_log.py``), other libraries' warnings in ``RUN/error.log``
(``warning_log.py``) and the per-generation callbacks of ``shaped_es.train`` (``callbacks.py``).

Leaves: nothing here imports the rest of the package (the run loop hands them what they write).
"""
