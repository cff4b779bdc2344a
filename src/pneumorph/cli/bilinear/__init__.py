"""The commands of the bilinear composite (``composite``) and the bimodal actuator it makes
(``bimodal``), chapter 3."""
