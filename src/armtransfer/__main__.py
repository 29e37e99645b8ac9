"""``python -m armtransfer``: the ``armtransfer`` command."""

from armtransfer.cli import run

if __name__ == "__main__":
    run()
