"""Command-line tools for documentation and development, each run as ``python -m cosim.tools.<name>``: pictures of
a finished run (``snapshot``, ``screenshot``), the controller's model figures (``controller_figures``), trajectory
files written without a simulation (``pour_motion``, ``scripted_pour``) and the model files derived from code
(``generate_models``). They sit above the library and import it; nothing in the library imports them."""
