"""Speed and accuracy benchmarks of every stage, each beside the alternative a user would
otherwise pick. Run ``python -m benchmarks`` (see RESULTS.md)."""
