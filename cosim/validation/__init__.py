"""Validation cases of the fluid core (and, once the robots exist, of the coupling) against analytic solutions
and published experiments. Each case module provides ``Params`` (frozen, validated), ``run(params) ->
CaseResult`` and ``plot(result, path)``; ``cosim validate`` drives them."""
